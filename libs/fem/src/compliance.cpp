// Compliance blocks from cached per-sphere solves of one factorisation.
#include "fahr/fem/compliance.h"

#include <algorithm>
#include <array>

#include "fahr/geometry/vector_clones.h"

namespace fahr::fem {
namespace {

// New spheres are solved in chunks of these sizes (largest first), so that
// CHOLMOD sees only four column counts and keeps a buffer set for each
// (CholmodSolver::kColumnCounts) instead of reallocating for every count.
constexpr std::array<std::size_t, 4> kChunkSpheres{8, 4, 2, 1};

// Row 3s + d of J times a solved column x: the motion of sphere s's centre
// along d (its weights over its nodes' DOFs).
double sphere_motion(const SphereLinks& links, std::uint32_t sphere, const double* x,
                     std::size_t d) {
  const auto nodes = links.nodes(sphere);
  const auto weights = links.weights(sphere);
  double sum = 0.0;
  for (std::size_t m = 0; m < nodes.size(); ++m)
    sum += weights[m] * x[3 * std::size_t{nodes[m]} + d];
  return sum;
}

// Adds J_s^T v to `column`: w_i v at node i's DOFs, fixed DOFs left at 0.
void add_spread(const SphereLinks& links, std::uint32_t sphere, const Eigen::Vector3d& v,
                std::span<const std::uint8_t> fixed_dof, double* column) {
  const auto nodes = links.nodes(sphere);
  const auto weights = links.weights(sphere);
  for (std::size_t m = 0; m < nodes.size(); ++m) {
    for (std::size_t d = 0; d < 3; ++d) {
      const std::size_t dof = 3 * std::size_t{nodes[m]} + d;
      if (fixed_dof[dof] == 0) column[dof] += weights[m] * v[static_cast<Eigen::Index>(d)];
    }
  }
}

}  // namespace

void ComplianceBlock::reserve(std::size_t dofs, std::size_t max_spheres) {
  dofs_ = dofs;
  max_spheres_ = max_spheres;
  // Half as many again as a block holds: spheres that leave the block for a
  // few steps and come back keep their columns.
  const std::size_t kept = max_spheres + max_spheres / 2;
  slots_.assign(kept, Slot{});
  columns_.assign(2 * dofs * 3 * kept, 0.0);
  reaches_.assign(2 * dofs * kept, 0);
  area_.assign(kept, 0);
  pending_.assign(max_spheres, Pending{});
  pending_count_ = 0;
  pending_pairs_.assign(9 * max_spheres * max_spheres, 0.0);
  pending_groups_.assign(max_spheres, HalfSolveColumns{});
  pending_gram_.assign(9 * max_spheres * max_spheres, 0.0);
  step_groups_.assign(max_spheres, HalfSolveColumns{});
  step_gram_.assign(9 * max_spheres * max_spheres, 0.0);
  pending_sphere_dofs_.reserve(std::size_t{3} * 16);
  last_request_.assign(max_spheres, 0);
  last_request_count_ = 0;
  sphere_dofs_.reserve(std::size_t{3} * 16);
  pairs_.assign(9 * kept * kept, 0.0);
  pair_known_.assign(kept * kept, 0);
  half_ = false;
  request_slots_.assign(max_spheres, 0);
  to_solve_.reserve(max_spheres);
  const std::size_t chunk = 3 * std::min(max_spheres, kChunkSpheres.front());
  rhs_.assign(dofs * chunk, 0.0);
  solution_.assign(dofs * chunk, 0.0);
  uses_ = 0;
}

std::size_t ComplianceBlock::slot_for(std::uint32_t sphere, std::uint64_t factorisation,
                                      bool& cached) {
  const std::uint64_t now = uses_;
  std::size_t oldest = slots_.size();
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    Slot& slot = slots_[i];
    // The sphere's columns, from this factorisation or an earlier one (then
    // refreshed within the budget, oldest first), or claimed in this call.
    if (slot.sphere == sphere && (slot.valid || slot.last_use == now)) {
      cached = slot.valid || slot.last_use == now;
      slot.last_use = now;
      return i;
    }
    if (slot.last_use != now &&
        (oldest == slots_.size() || slot.last_use < slots_[oldest].last_use))
      oldest = i;
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
    for (std::size_t d = 0; d < 3; ++d) {
      add_spread(links, slots_[slots[s]].sphere,
                 Eigen::Vector3d::Unit(static_cast<Eigen::Index>(d)), fixed_dof,
                 rhs_.data() + dofs_ * (3 * s + d));
    }
  }
  warp.solve_columns(factor, {rhs_.data(), dofs_ * columns}, {solution_.data(), dofs_ * columns},
                     static_cast<int>(columns));
  for (std::size_t s = 0; s < slots.size(); ++s) {
    slots_[slots[s]].factorisation = factor.factorisations();
    const auto from = solution_.begin() + static_cast<std::ptrdiff_t>(dofs_ * 3 * s);
    std::copy(from, from + static_cast<std::ptrdiff_t>(3 * dofs_), column(slots[s], 0));
    slots_[slots[s]].valid = true;
  }
}

template <typename Factor>
std::size_t ComplianceBlock::place_half_into(std::size_t slot, std::size_t area,
                                             std::uint32_t sphere, const SphereLinks& links,
                                             std::span<const std::uint8_t> fixed_dof,
                                             Factor& factor,
                                             std::vector<std::uint32_t>& sphere_dofs) {
  const auto nodes = links.nodes(sphere);
  const auto weights = links.weights(sphere);
  sphere_dofs.clear();
  for (const std::uint32_t node : nodes) {
    for (std::uint32_t d = 0; d < 3; ++d) {
      const std::uint32_t dof = 3 * node + d;
      if (fixed_dof[dof] == 0) sphere_dofs.push_back(dof);
    }
  }
  int* reach = reach_in(slot, area);
  const std::size_t count = factor.reach(sphere_dofs, {reach, dofs_});
  const std::span<const int> supernodes{reach, count};
  for (std::size_t d = 0; d < 3; ++d) {
    double* y = column_in(slot, area, d);
    for (const int k : supernodes)
      std::fill(y + factor.supernode_first(k), y + factor.supernode_end(k), 0.0);
    // P J_s^T along d: w_i on node i's DOF d, at that DOF's row in the ordering.
    for (std::size_t m = 0; m < nodes.size(); ++m) {
      const std::size_t dof = 3 * std::size_t{nodes[m]} + d;
      if (fixed_dof[dof] == 0) y[factor.permuted(dof)] += weights[m];
    }
  }
  return count;
}

// The slots of to_solve_ solved on the factor, their products with the
// other slots computed again when asked for. One slot reads L along its
// reach (forward3_on_reach); several go through it in one pass, their
// products with each other from the same pass.
void ComplianceBlock::solve_halves(const SphereLinks& links,
                                   std::span<const std::uint8_t> fixed_dof, CholmodSolver& factor) {
  const std::size_t solving = to_solve_.size();
  if (solving == 0) return;
  const std::size_t count = slots_.size();
  const std::uint64_t factorisation = factor.factorisations();
  for (std::size_t i = 0; i < solving; ++i) {
    const std::size_t slot = to_solve_[i];
    Slot& kept = slots_[slot];
    kept.reach =
        place_half_into(slot, area_[slot], kept.sphere, links, fixed_dof, factor, sphere_dofs_);
    kept.factorisation = factorisation;
    kept.valid = true;
    for (std::size_t other = 0; other < count; ++other) {
      pair_known_[slot * count + other] = 0;
      pair_known_[other * count + slot] = 0;
    }
    step_groups_[i] = HalfSolveColumns{
        .y = column(slot, 0), .reach = reach_in(slot, area_[slot]), .count = kept.reach};
  }
  if (solving == 1) {
    const HalfSolveColumns& one = step_groups_.front();
    factor.forward3_on_reach({one.reach, one.count}, {one.y, 3 * dofs_});
    return;
  }
  const std::size_t width = 3 * solving;
  factor.forward_gram_on_reach({step_groups_.data(), solving}, step_work_,
                               {step_gram_.data(), width * width});
  for (std::size_t i = 0; i < solving; ++i) {
    for (std::size_t j = 0; j < solving; ++j) {
      double* block = pairs_.data() + 9 * (to_solve_[i] * count + to_solve_[j]);
      for (std::size_t d = 0; d < 3; ++d) {
        for (std::size_t e = 0; e < 3; ++e)
          block[3 * d + e] = step_gram_[(3 * i + d) * width + 3 * j + e];
      }
      pair_known_[to_solve_[i] * count + to_solve_[j]] = 1;
    }
  }
}

// Y_s^T Y_t (row-major 3x3, into `sum`) of two half solves, summed over
// the supernodes both reach (a merge of two ascending lists); `bounds` are
// the supernodes' column ranges. Partial sums in kLanes interleaved lanes
// (vector registers), added in a fixed order at the end: the same bits on
// every run and on either thread. External linkage: target_clones makes an
// ifunc of it.
FAHR_VECTOR_CLONES void reach_product(const int* bounds, const double* const ys[3], const int* a,
                                      const int* a_end, const double* const yt[3], const int* b,
                                      const int* b_end, double sum[9]) {
  constexpr std::size_t kLanes = 4;
  double lanes[9][kLanes] = {};
  for (std::size_t i = 0; i < 9; ++i) sum[i] = 0.0;
  while (a != a_end && b != b_end) {
    if (*a < *b) {
      ++a;
    } else if (*b < *a) {
      ++b;
    } else {
      const auto first = std::size_t(bounds[*a]);
      const auto end = std::size_t(bounds[*a + 1]);
      std::size_t j = first;
      for (; j + kLanes <= end; j += kLanes) {
        for (std::size_t d = 0; d < 3; ++d) {
          for (std::size_t e = 0; e < 3; ++e) {
            for (std::size_t q = 0; q < kLanes; ++q)
              lanes[3 * d + e][q] += ys[d][j + q] * yt[e][j + q];
          }
        }
      }
      for (; j < end; ++j) {
        for (std::size_t d = 0; d < 3; ++d) {
          for (std::size_t e = 0; e < 3; ++e) sum[3 * d + e] += ys[d][j] * yt[e][j];
        }
      }
      ++a;
      ++b;
    }
  }
  for (std::size_t i = 0; i < 9; ++i) {
    for (std::size_t q = 0; q < kLanes; ++q) sum[i] += lanes[i][q];
  }
}

const double* ComplianceBlock::half_product(std::size_t s, std::size_t t,
                                            const CholmodSolver& factor) {
  const std::size_t count = slots_.size();
  double* block = pairs_.data() + 9 * (s * count + t);
  if (pair_known_[s * count + t] != 0) return block;
  const double* ys[3] = {column(s, 0), column(s, 1), column(s, 2)};
  const double* yt[3] = {column(t, 0), column(t, 1), column(t, 2)};
  double sum[9];
  reach_product(factor.supernode_bounds(), ys, reach(s), reach(s) + slots_[s].reach, yt, reach(t),
                reach(t) + slots_[t].reach, sum);
  double* mirror = pairs_.data() + 9 * (t * count + s);
  for (std::size_t d = 0; d < 3; ++d) {
    for (std::size_t e = 0; e < 3; ++e) {
      block[3 * d + e] = sum[3 * d + e];
      mirror[3 * e + d] = sum[3 * d + e];
    }
  }
  pair_known_[s * count + t] = 1;
  pair_known_[t * count + s] = 1;
  return block;
}

std::size_t ComplianceBlock::begin_refresh(const SphereLinks& links,
                                           std::span<const std::uint8_t> fixed_dof) {
  pending_count_ = 0;
  if (!half_) return 0;
  for (std::size_t r = 0; r < last_request_count_; ++r) {
    const std::size_t slot = last_request_[r];
    const Slot& kept = slots_[slot];
    if (!kept.valid || kept.sphere >= links.size()) continue;
    pending_[pending_count_++] = Pending{.slot = slot, .sphere = kept.sphere};
  }
  pending_links_ = &links;
  pending_fixed_dof_ = fixed_dof;
  return pending_count_;
}

void ComplianceBlock::refresh_on(CholmodSolver::NewFactor& factor) {
  if (pending_count_ == 0 || !factor.sparse_forward_ready()) {
    pending_count_ = 0;
    return;
  }
  // Into each slot's buffer not in use: the step reads and writes only the
  // other until adopt_refresh(). All of them in one pass over the factor:
  // the supernodes near the root, which every sphere reaches, are read once
  // instead of once per sphere, and their products come as one Gram matrix.
  for (std::size_t i = 0; i < pending_count_; ++i) {
    Pending& p = pending_[i];
    const std::size_t spare = 1 - area_[p.slot];
    p.reach = place_half_into(p.slot, spare, p.sphere, *pending_links_, pending_fixed_dof_, factor,
                              pending_sphere_dofs_);
    pending_groups_[i] = HalfSolveColumns{
        .y = column_in(p.slot, spare, 0), .reach = reach_in(p.slot, spare), .count = p.reach};
  }
  const std::size_t width = 3 * pending_count_;
  factor.forward_gram_on_reach({pending_groups_.data(), pending_count_}, pending_work_,
                               {pending_gram_.data(), width * width});
  for (std::size_t i = 0; i < pending_count_; ++i) {
    for (std::size_t j = i; j < pending_count_; ++j) {
      double* sum = pending_pairs_.data() + 9 * (i * pending_count_ + j);
      for (std::size_t d = 0; d < 3; ++d) {
        for (std::size_t e = 0; e < 3; ++e)
          sum[3 * d + e] = pending_gram_[(3 * i + d) * width + 3 * j + e];
      }
    }
  }
}

void ComplianceBlock::adopt_refresh(const CholmodSolver& factor) {
  const std::size_t listed = pending_count_;
  pending_count_ = 0;
  if (listed == 0 || !half_ || !factor.sparse_forward_ready()) return;
  const std::size_t count = slots_.size();
  const std::uint64_t factorisation = factor.factorisations();
  // A slot whose sphere left it (another took it) keeps what it has; the
  // others take the new columns, and their products with the others are
  // computed again when asked for.
  for (std::size_t i = 0; i < listed; ++i) {
    Pending& p = pending_[i];
    Slot& kept = slots_[p.slot];
    p.adopted = kept.sphere == p.sphere;
    if (!p.adopted) continue;
    area_[p.slot] = static_cast<std::uint8_t>(1 - area_[p.slot]);
    kept.reach = p.reach;
    kept.factorisation = factorisation;
    kept.valid = true;
    for (std::size_t other = 0; other < count; ++other) {
      pair_known_[p.slot * count + other] = 0;
      pair_known_[other * count + p.slot] = 0;
    }
    ++adopted_;
  }
  for (std::size_t i = 0; i < listed; ++i) {
    const Pending& p = pending_[i];
    if (!p.adopted) continue;
    for (std::size_t j = i; j < listed; ++j) {
      const Pending& q = pending_[j];
      if (!q.adopted) continue;
      const double* sum = pending_pairs_.data() + 9 * (i * listed + j);
      double* block = pairs_.data() + 9 * (p.slot * count + q.slot);
      double* mirror = pairs_.data() + 9 * (q.slot * count + p.slot);
      for (std::size_t d = 0; d < 3; ++d) {
        for (std::size_t e = 0; e < 3; ++e) {
          block[3 * d + e] = sum[3 * d + e];
          mirror[3 * e + d] = sum[3 * d + e];
        }
      }
      pair_known_[p.slot * count + q.slot] = 1;
      pair_known_[q.slot * count + p.slot] = 1;
    }
  }
}

bool ComplianceBlock::compute(std::span<const std::uint32_t> spheres, const SphereLinks& links,
                              std::span<const std::uint8_t> fixed_dof, CholmodSolver& factor,
                              WarpedFactor& warp, double time_step_s, std::span<float> out) {
  const std::size_t k = spheres.size();
  const std::size_t rows = 3 * k;
  if (k == 0) return true;
  if (k > max_spheres_ || out.size() < rows * rows || !factor.factorized()) return false;
  for (const std::uint32_t s : spheres) {
    if (s >= links.size()) return false;
  }
  ++uses_;
  const bool half_solves = factor.sparse_forward_ready() && !warp.enabled();
  if (warp.enabled() || half_solves != half_) {
    // Q A^-1 Q^T changes with the rotations every step, and half and full
    // solves do not mix: nothing kept is used.
    for (Slot& slot : slots_) slot.valid = false;
    half_ = half_solves;
  }
  const std::uint64_t factorisation = factor.factorisations();
  to_solve_.clear();
  for (std::size_t s = 0; s < k; ++s) {
    bool cached = false;
    request_slots_[s] = slot_for(spheres[s], factorisation, cached);
    if (!cached) to_solve_.push_back(request_slots_[s]);
  }
  // Spheres new to the block are solved in full; columns of an earlier
  // factorisation are refreshed up to the budget a call: half of it to the
  // first stale spheres in request order (the rows the tick solved, the
  // deepest first: those whose W sets the force), the rest to the stalest,
  // so that no column lags without bound.
  std::size_t refresh = 0;
  const std::size_t leading = (refresh_per_call_ + 1) / 2;
  for (std::size_t s = 0; s < k && refresh < leading; ++s) {
    Slot& slot = slots_[request_slots_[s]];
    if (!slot.valid || slot.factorisation == factorisation) continue;
    slot.factorisation = factorisation;
    to_solve_.push_back(request_slots_[s]);
    ++refresh;
  }
  while (refresh < refresh_per_call_) {
    std::size_t stalest = slots_.size();
    for (std::size_t s = 0; s < k; ++s) {
      const Slot& slot = slots_[request_slots_[s]];
      if (!slot.valid || slot.factorisation == factorisation) continue;
      if (stalest == slots_.size() || slot.factorisation < slots_[stalest].factorisation)
        stalest = request_slots_[s];
    }
    if (stalest == slots_.size()) break;
    slots_[stalest].factorisation = factorisation;
    to_solve_.push_back(stalest);
    ++refresh;
  }
  for (std::size_t s = 0; s < k; ++s) {
    const std::uint64_t lag = factorisation - slots_[request_slots_[s]].factorisation;
    oldest_lag_ = std::max<std::uint64_t>(oldest_lag_, lag);
    last_request_[s] = request_slots_[s];
  }
  last_request_count_ = k;
  const double h2 = time_step_s * time_step_s;
  if (half_solves) {
    solve_halves(links, fixed_dof, factor);
    for (std::size_t s = 0; s < k; ++s) {
      for (std::size_t t = 0; t < k; ++t) {
        const double* block = half_product(request_slots_[s], request_slots_[t], factor);
        for (std::size_t d = 0; d < 3; ++d) {
          for (std::size_t e = 0; e < 3; ++e)
            out[(3 * s + d) * rows + 3 * t + e] = static_cast<float>(h2 * block[3 * d + e]);
        }
      }
    }
    return true;
  }
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
  for (std::size_t t = 0; t < rows; ++t) {
    const double* x = column(request_slots_[t / 3], t % 3);
    for (std::size_t s = 0; s < k; ++s) {
      for (std::size_t d = 0; d < 3; ++d) {
        out[(3 * s + d) * rows + t] =
            static_cast<float>(h2 * sphere_motion(links, spheres[s], x, d));
      }
    }
  }
  return true;
}

bool ComplianceBlock::compute_along(std::span<const std::uint32_t> spheres,
                                    std::span<const Eigen::Vector3d> normals,
                                    const SphereLinks& links,
                                    std::span<const std::uint8_t> fixed_dof, CholmodSolver& factor,
                                    WarpedFactor& warp, double time_step_s, std::span<float> out) {
  const std::size_t k = spheres.size();
  if (k == 0) return true;
  if (k > max_spheres_ || normals.size() < k || out.size() < 3 * k * k || !factor.factorized())
    return false;
  for (const std::uint32_t s : spheres) {
    if (s >= links.size()) return false;
  }
  // The columns of the 3x3 blocks' cache are not these: leave it alone.
  const double h2 = time_step_s * time_step_s;
  const std::size_t per_chunk =
      rhs_.size() / dofs_;  // columns a chunk holds (3 x kChunkSpheres.front())
  for (std::size_t done = 0; done < k;) {
    // Column counts CHOLMOD keeps buffers for: the blocks' 24, 12, 6, 3, then 2 and 1.
    std::size_t chunk = 1;
    for (const std::size_t c :
         {per_chunk, per_chunk / 2, per_chunk / 4, per_chunk / 8, std::size_t{2}}) {
      if (c > 0 && c <= k - done) {
        chunk = c;
        break;
      }
    }
    // B = J^T N: column t holds w_i n_t at node i's DOFs.
    std::fill(rhs_.begin(), rhs_.begin() + static_cast<std::ptrdiff_t>(dofs_ * chunk), 0.0);
    for (std::size_t c = 0; c < chunk; ++c) {
      add_spread(links, spheres[done + c], normals[done + c], fixed_dof, rhs_.data() + dofs_ * c);
    }
    warp.solve_columns(factor, {rhs_.data(), dofs_ * chunk}, {solution_.data(), dofs_ * chunk},
                       static_cast<int>(chunk));
    for (std::size_t c = 0; c < chunk; ++c) {
      const double* x = solution_.data() + dofs_ * c;
      const std::size_t t = done + c;
      for (std::size_t s = 0; s < k; ++s) {
        for (std::size_t d = 0; d < 3; ++d) {
          out[(3 * s + d) * k + t] =
              static_cast<float>(h2 * sphere_motion(links, spheres[s], x, d));
        }
      }
    }
    done += chunk;
  }
  return true;
}

}  // namespace fahr::fem
