// Compliance blocks from cached per-sphere solves of one factorisation.
#include "fahr/fem/compliance.h"

#include <algorithm>
#include <array>

namespace fahr::fem {
namespace {

// New spheres are solved in chunks of these sizes (largest first), so that
// CHOLMOD sees only four column counts and keeps a buffer set for each
// (CholmodSolver::kColumnCounts) instead of reallocating for every count.
constexpr std::array<std::size_t, 4> kChunkSpheres{8, 4, 2, 1};

}  // namespace

void ComplianceBlock::reserve(std::size_t dofs, std::size_t max_spheres) {
  dofs_ = dofs;
  max_spheres_ = max_spheres;
  // Half as many again as a block holds: spheres that leave the block for a
  // few steps and come back keep their columns.
  const std::size_t kept = max_spheres + max_spheres / 2;
  slots_.assign(kept, Slot{});
  columns_.assign(dofs * 3 * kept, 0.0);
  request_slots_.assign(max_spheres, 0);
  to_solve_.reserve(max_spheres);
  const std::size_t chunk = 3 * std::min(max_spheres, kChunkSpheres.front());
  rhs_.assign(dofs * chunk, 0.0);
  solution_.assign(dofs * chunk, 0.0);
  uses_ = 0;
  last_solved_ = 0;
}

std::size_t ComplianceBlock::slot_for(std::uint32_t sphere, std::uint64_t factorisation, bool& cached) {
  const std::uint64_t now = uses_;
  std::size_t oldest = slots_.size();
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    Slot& slot = slots_[i];
    // A slot already claimed in this call (last_use == now) for the same
    // sphere is shared, solved or not.
    if (slot.sphere == sphere && slot.factorisation == factorisation && (slot.valid || slot.last_use == now)) {
      cached = slot.valid || slot.last_use == now;
      slot.last_use = now;
      return i;
    }
    if (slot.last_use != now && (oldest == slots_.size() || slot.last_use < slots_[oldest].last_use)) oldest = i;
  }
  // There are more slots than spheres in one request, so one is free.
  Slot& slot = slots_[oldest];
  slot = Slot{.sphere = sphere, .factorisation = factorisation, .last_use = now, .valid = false};
  cached = false;
  return oldest;
}

void ComplianceBlock::solve_chunk(std::span<const std::size_t> slots, const SphereLinks& links,
                                  std::span<const std::uint8_t> fixed_dof, CholmodSolver& factor,
                                  WarpedFactor& warp) {
  const std::size_t columns = 3 * slots.size();
  // B = J^T: column 3s + d holds w_i at row 3 n_i + d.
  std::fill(rhs_.begin(), rhs_.begin() + static_cast<std::ptrdiff_t>(dofs_ * columns), 0.0);
  for (std::size_t s = 0; s < slots.size(); ++s) {
    const std::uint32_t sphere = slots_[slots[s]].sphere;
    const auto nodes = links.nodes(sphere);
    const auto weights = links.weights(sphere);
    for (std::size_t d = 0; d < 3; ++d) {
      double* column = rhs_.data() + dofs_ * (3 * s + d);
      for (std::size_t m = 0; m < nodes.size(); ++m) {
        const std::size_t dof = 3 * std::size_t{nodes[m]} + d;
        if (fixed_dof[dof] == 0) column[dof] += weights[m];
      }
    }
  }
  warp.solve_columns(factor, {rhs_.data(), dofs_ * columns}, {solution_.data(), dofs_ * columns},
                     static_cast<int>(columns));
  for (std::size_t s = 0; s < slots.size(); ++s) {
    const auto from = solution_.begin() + static_cast<std::ptrdiff_t>(dofs_ * 3 * s);
    std::copy(from, from + static_cast<std::ptrdiff_t>(3 * dofs_),
              columns_.begin() + static_cast<std::ptrdiff_t>(dofs_ * 3 * slots[s]));
    slots_[slots[s]].valid = true;
  }
}

bool ComplianceBlock::compute(std::span<const std::uint32_t> spheres, const SphereLinks& links,
                              std::span<const std::uint8_t> fixed_dof, CholmodSolver& factor,
                              WarpedFactor& warp, double time_step_s, std::span<float> out) {
  const std::size_t k = spheres.size();
  const std::size_t rows = 3 * k;
  last_solved_ = 0;
  if (k == 0) return true;
  if (k > max_spheres_ || out.size() < rows * rows || !factor.factorized()) return false;
  for (const std::uint32_t s : spheres) {
    if (s >= links.size()) return false;
  }
  ++uses_;
  if (warp.enabled()) {
    // Q A^-1 Q^T changes with the rotations every step: nothing is kept.
    for (Slot& slot : slots_) slot.valid = false;
  }
  const std::uint64_t factorisation = factor.factorisations();
  to_solve_.clear();
  for (std::size_t s = 0; s < k; ++s) {
    bool cached = false;
    request_slots_[s] = slot_for(spheres[s], factorisation, cached);
    if (!cached) to_solve_.push_back(request_slots_[s]);
  }
  last_solved_ = to_solve_.size();
  for (std::size_t done = 0; done < to_solve_.size();) {
    const std::size_t left = to_solve_.size() - done;
    std::size_t chunk = kChunkSpheres.back();
    for (const std::size_t c : kChunkSpheres) {
      if (c <= left && 3 * c * dofs_ <= rhs_.size()) {
        chunk = c;
        break;
      }
    }
    solve_chunk({to_solve_.data() + done, chunk}, links, fixed_dof, factor, warp);
    done += chunk;
  }
  // W = h^2 J X: row 3s + d of J dotted with column 3t + e of X.
  const double h2 = time_step_s * time_step_s;
  for (std::size_t t = 0; t < rows; ++t) {
    const double* x = column(request_slots_[t / 3], t % 3);
    for (std::size_t s = 0; s < k; ++s) {
      const auto nodes = links.nodes(spheres[s]);
      const auto weights = links.weights(spheres[s]);
      for (std::size_t d = 0; d < 3; ++d) {
        double sum = 0.0;
        for (std::size_t m = 0; m < nodes.size(); ++m) sum += weights[m] * x[3 * std::size_t{nodes[m]} + d];
        out[(3 * s + d) * rows + t] = static_cast<float>(h2 * sum);
      }
    }
  }
  return true;
}

}  // namespace fahr::fem
