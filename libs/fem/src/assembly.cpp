// Pattern building once, value writing every step.
#include "fahr/fem/assembly.h"

#include <algorithm>
#include <cstring>

namespace fahr::fem {
namespace {

std::vector<std::vector<std::uint32_t>> node_neighbours(std::size_t node_count,
                                                        const ElementRest& rest) {
  std::vector<std::vector<std::uint32_t>> neighbours(node_count);
  for (std::size_t i = 0; i < node_count; ++i)
    neighbours[i].push_back(static_cast<std::uint32_t>(i));
  for (const Tet& tet : rest.tets) {
    for (const std::uint32_t a : tet) {
      for (const std::uint32_t b : tet) neighbours[a].push_back(b);
    }
  }
  for (auto& list : neighbours) {
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  }
  return neighbours;
}

}  // namespace

void SystemAssembly::build(std::size_t node_count, const ElementRest& rest,
                           std::span<const std::uint8_t> fixed_dof) {
  const auto neighbours = node_neighbours(node_count, rest);
  const std::size_t dofs = 3 * node_count;
  std::vector<int> outer(dofs + 1, 0);
  for (std::size_t j = 0; j < node_count; ++j) {
    for (std::size_t c = 0; c < 3; ++c) {
      outer[3 * j + c + 1] = outer[3 * j + c] + static_cast<int>(3 * neighbours[j].size());
    }
  }
  const auto nnz = static_cast<std::size_t>(outer[dofs]);
  std::vector<int> inner(nnz);
  for (std::size_t j = 0; j < node_count; ++j) {
    for (std::size_t c = 0; c < 3; ++c) {
      auto k = static_cast<std::size_t>(outer[3 * j + c]);
      for (const std::uint32_t i : neighbours[j]) {
        for (std::size_t r = 0; r < 3; ++r) inner[k++] = static_cast<int>(3 * std::size_t{i} + r);
      }
    }
  }
  const auto dofs_index = static_cast<Eigen::Index>(dofs);
  a_.resize(dofs_index, dofs_index);
  a_.resizeNonZeros(static_cast<Eigen::Index>(nnz));
  std::copy(outer.begin(), outer.end(), a_.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), a_.innerIndexPtr());
  std::fill(a_.valuePtr(), a_.valuePtr() + nnz, 0.0);

  auto rank_of = [&](std::uint32_t column_node, std::uint32_t row_node) {
    const auto& list = neighbours[column_node];
    return static_cast<std::size_t>(std::lower_bound(list.begin(), list.end(), row_node) -
                                    list.begin());
  };
  block_column_start_.resize(48 * rest.size());
  for (std::size_t e = 0; e < rest.size(); ++e) {
    const Tet& tet = rest.tets[e];
    for (std::size_t a = 0; a < 4; ++a) {
      for (std::size_t b = 0; b < 4; ++b) {
        const std::size_t rank = rank_of(tet[b], tet[a]);
        for (std::size_t c = 0; c < 3; ++c) {
          block_column_start_[48 * e + 12 * a + 3 * b + c] = static_cast<std::uint32_t>(
              static_cast<std::size_t>(outer[3 * std::size_t{tet[b]} + c]) + 3 * rank);
        }
      }
    }
  }
  diagonal_index_.resize(dofs);
  for (std::size_t j = 0; j < node_count; ++j) {
    const std::size_t rank = rank_of(static_cast<std::uint32_t>(j), static_cast<std::uint32_t>(j));
    for (std::size_t c = 0; c < 3; ++c) {
      diagonal_index_[3 * j + c] = outer[3 * j + c] + static_cast<int>(3 * rank + c);
    }
  }
  fixed_off_diagonal_.clear();
  fixed_diagonal_dof_.clear();
  fixed_dof_.assign(fixed_dof.begin(), fixed_dof.end());
  fixed_dof_.resize(dofs, 0);
  tets_ = rest.tets;
  base_diagonal_.assign(dofs, 0.0);
  for (std::size_t col = 0; col < dofs; ++col) {
    if (fixed_dof[col] != 0) fixed_diagonal_dof_.push_back(static_cast<int>(col));
    for (int k = outer[col]; k < outer[col + 1]; ++k) {
      const auto row = static_cast<std::size_t>(inner[static_cast<std::size_t>(k)]);
      if (row != col && (fixed_dof[row] != 0 || fixed_dof[col] != 0))
        fixed_off_diagonal_.push_back(k);
    }
  }
}

void SystemAssembly::assemble(const ElementRest& rest, std::span<const Eigen::Matrix3d> rotations,
                              const LameParameters& lame, std::span<const double> mass_per_dof_kg,
                              double mass_scale, double stiffness_scale,
                              std::span<const double> element_scales) {
  zero();
  double* values = a_.valuePtr();
  for (std::size_t e = 0; e < rest.size(); ++e) {
    // Rotated gradients r_a = R g_a give R K_ab R^T =
    // V (lambda r_a r_b^T + mu r_b r_a^T + mu (g_a . g_b) I).
    const Eigen::Matrix<double, 3, 4> g = shape_gradients(rest.dm_inv[e]);
    const Eigen::Matrix<double, 3, 4> r = rotations[e] * g;
    double scale = stiffness_scale * rest.volume_m3[e];
    if (!element_scales.empty()) scale *= element_scales[e];
    const double lambda = scale * lame.lambda_pa;
    const double mu = scale * lame.mu_pa;
    const std::uint32_t* starts = &block_column_start_[48 * e];
    for (int a = 0; a < 4; ++a) {
      for (int b = 0; b < 4; ++b) {
        const double shear_diagonal = mu * g.col(a).dot(g.col(b));
        for (int c = 0; c < 3; ++c) {
          double* column = values + starts[12 * a + 3 * b + c];
          const double rbc = r(c, b);
          const double rac = r(c, a);
          for (int d = 0; d < 3; ++d) {
            column[d] += lambda * r(d, a) * rbc + mu * r(d, b) * rac;
          }
          column[c] += shear_diagonal;
        }
      }
    }
  }
  add_mass(mass_per_dof_kg, mass_scale);
}

void SystemAssembly::zero() {
  std::memset(a_.valuePtr(), 0, sizeof(double) * static_cast<std::size_t>(a_.nonZeros()));
}

void SystemAssembly::add_element(std::size_t element, const Matrix12d& k, double scale) {
  double* values = a_.valuePtr();
  const std::uint32_t* starts = &block_column_start_[48 * element];
  for (Eigen::Index a = 0; a < 4; ++a) {
    for (Eigen::Index b = 0; b < 4; ++b) {
      for (Eigen::Index c = 0; c < 3; ++c) {
        // Column c of block (a, b): rows 3a..3a+2 of K's column 3b + c.
        double* column = values + starts[12 * a + 3 * b + c];
        const double* source = k.data() + 12 * (3 * b + c) + 3 * a;
        for (int d = 0; d < 3; ++d) column[d] += scale * source[d];
      }
    }
  }
}

void SystemAssembly::add_mass(std::span<const double> mass_per_dof_kg, double mass_scale) {
  double* values = a_.valuePtr();
  const std::size_t dofs = diagonal_index_.size();
  for (std::size_t k = 0; k < dofs; ++k) {
    values[diagonal_index_[k]] += mass_scale * mass_per_dof_kg[k];
  }
  for (const int k : fixed_off_diagonal_) values[k] = 0.0;
  // A fixed DOF keeps only its mass term: the row reads m v = 0, and the
  // diagonal stays of the size of its neighbours for conditioning (the body
  // gives massless nodes a representative mass for this).
  for (const int dof : fixed_diagonal_dof_) {
    const auto k = static_cast<std::size_t>(dof);
    values[diagonal_index_[k]] = mass_scale * mass_per_dof_kg[k];
  }
}

// Within column 3 node + c the node's own three rows are contiguous (rows
// are sorted and the node's DOFs are consecutive), so the block's column c
// starts c entries above the diagonal.
void SystemAssembly::add_supports(std::span<const NodeSupport> nodes,
                                  std::span<const TetSupport> tets, double ratio) {
  if (nodes.empty() && tets.empty()) return;
  double* values = a_.valuePtr();
  const std::size_t dofs = diagonal_index_.size();
  for (std::size_t k = 0; k < dofs; ++k) base_diagonal_[k] = values[diagonal_index_[k]];
  const auto node_diagonal = [&](std::size_t node) {
    return (base_diagonal_[3 * node] + base_diagonal_[3 * node + 1] +
            base_diagonal_[3 * node + 2]) /
           3.0;
  };
  const auto free_node = [&](std::size_t node) {
    return 3 * node + 2 < dofs && fixed_dof_[3 * node] == 0;
  };
  for (const NodeSupport& support : nodes) {
    const std::size_t node = support.node;
    if (!free_node(node)) continue;
    const double k = ratio * node_diagonal(node);
    for (int c = 0; c < 3; ++c) {
      double* column = values + diagonal_index_[3 * node + static_cast<std::size_t>(c)] - c;
      for (int r = 0; r < 3; ++r) column[r] += k * support.normal[r] * support.normal[c];
    }
  }
  for (const TetSupport& support : tets) {
    if (support.tet >= tets_.size()) continue;
    const Tet& tet = tets_[support.tet];
    double diagonal = 0.0;
    int free = 0;
    for (std::size_t a = 0; a < 4; ++a) {
      if (!free_node(tet[a]) || support.direction[a].squaredNorm() == 0.0) continue;
      diagonal += node_diagonal(tet[a]);
      ++free;
    }
    if (free == 0) continue;
    const double k = ratio * diagonal / free;
    const std::uint32_t* starts = &block_column_start_[48 * std::size_t{support.tet}];
    for (std::size_t a = 0; a < 4; ++a) {
      if (!free_node(tet[a])) continue;
      for (std::size_t b = 0; b < 4; ++b) {
        if (!free_node(tet[b])) continue;
        for (std::size_t c = 0; c < 3; ++c) {
          double* column = values + starts[12 * a + 3 * b + c];
          const double dbc = k * support.direction[b][static_cast<Eigen::Index>(c)];
          for (Eigen::Index d = 0; d < 3; ++d) column[d] += support.direction[a][d] * dbc;
        }
      }
    }
  }
}

}  // namespace fahr::fem
