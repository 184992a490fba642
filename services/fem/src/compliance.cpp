// Compliance blocks from one multi-column CHOLMOD solve.
#include "fahr/fem/compliance.h"

#include <algorithm>

namespace fahr::fem {

void ComplianceBlock::reserve(std::size_t dofs, std::size_t max_spheres) {
  dofs_ = dofs;
  max_spheres_ = max_spheres;
  rhs_.assign(dofs * 3 * max_spheres, 0.0);
  solution_.assign(dofs * 3 * max_spheres, 0.0);
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
  // B = J^T: column 3s + d holds w_i at row 3 n_i + d.
  std::fill(rhs_.begin(), rhs_.begin() + static_cast<std::ptrdiff_t>(dofs_ * rows), 0.0);
  for (std::size_t s = 0; s < k; ++s) {
    const auto nodes = links.nodes(spheres[s]);
    const auto weights = links.weights(spheres[s]);
    for (std::size_t d = 0; d < 3; ++d) {
      double* column = rhs_.data() + dofs_ * (3 * s + d);
      for (std::size_t m = 0; m < nodes.size(); ++m) {
        const std::size_t dof = 3 * std::size_t{nodes[m]} + d;
        if (fixed_dof[dof] == 0) column[dof] += weights[m];
      }
    }
  }
  warp.solve_columns(factor, rhs_, solution_, static_cast<int>(rows));
  // W = h^2 J X: row 3s + d of J dotted with column 3t + e of X.
  const double h2 = time_step_s * time_step_s;
  for (std::size_t t = 0; t < rows; ++t) {
    const double* column = solution_.data() + dofs_ * t;
    for (std::size_t s = 0; s < k; ++s) {
      const auto nodes = links.nodes(spheres[s]);
      const auto weights = links.weights(spheres[s]);
      for (std::size_t d = 0; d < 3; ++d) {
        double sum = 0.0;
        for (std::size_t m = 0; m < nodes.size(); ++m) {
          sum += weights[m] * column[3 * std::size_t{nodes[m]} + d];
        }
        out[(3 * s + d) * rows + t] = static_cast<float>(h2 * sum);
      }
    }
  }
  return true;
}

}  // namespace fahr::fem
