// The system matrix A = mass_scale M + stiffness_scale K on a sparsity
// pattern fixed at set-up, written in place through an element-to-non-zero
// map: K the corotated linear stiffness R K0 R^T, or any per-element 12x12
// (the hyperelastic tangent).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <span>
#include <vector>

#include "fahr/fem/element_rest.h"
#include "fahr/fem/hyperelastic_element.h"
#include "fahr/fem/material.h"
#include "fahr/fem/obstacle_support.h"

namespace fahr::fem {

// Column-major, both triangles stored (CG multiplies with it; CHOLMOD reads
// the upper triangle only). Indices are int, as CHOLMOD_INT expects.
using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

class SystemAssembly {
 public:
  // Builds the pattern of all node pairs sharing a tet (3x3 blocks) and the
  // map from element blocks to non-zeros. fixed_dof[k] != 0 decouples DOF k:
  // its row and column are zero apart from a positive diagonal.
  void build(std::size_t node_count, const ElementRest& rest,
             std::span<const std::uint8_t> fixed_dof);

  // Writes A = mass_scale diag(m) + stiffness_scale sum_e s_e R_e K0_e R_e^T.
  // mass_per_dof_kg has one entry per DOF. element_scales: s_e, one per
  // element (compression_stiffening.h), or empty for s_e = 1 (the linear
  // material, computed exactly as without scales). No allocation.
  void assemble(const ElementRest& rest, std::span<const Eigen::Matrix3d> rotations,
                const LameParameters& lame, std::span<const double> mass_per_dof_kg,
                double mass_scale, double stiffness_scale,
                std::span<const double> element_scales = {});

  // The same A from element matrices: zero(), add_element() for each
  // element, then add_mass() once. k_e is element e's 12x12 stiffness in
  // hyperelastic_element.h's DOF order (symmetric: each block is read as
  // stored), added as scale k_e. No allocation.
  void zero();
  void add_element(std::size_t element, const Matrix12d& k, double scale);
  // Adds mass_scale diag(m) and decouples the fixed DOFs (their rows and
  // columns zero, the diagonal mass_scale m): the end of an assembly.
  void add_mass(std::span<const double> mass_per_dof_kg, double mass_scale);

  // Adds the support springs (obstacle_support.h): k n n^T to the diagonal
  // block of each held node, and k d d^T over the four nodes' blocks of each
  // held tet (d its unit 12-vector, zero on fixed nodes). k is `ratio` times
  // the mean diagonal entry of the nodes the spring acts on, as assembled
  // before any spring (so a spring is that much stiffer than its nodes' own
  // inertia and elasticity in the step, whatever the units and time step,
  // and the springs do not depend on their order). Fixed nodes are skipped
  // (their rows must stay m v = 0). The end of an assembly, after
  // add_mass(). No allocation.
  void add_supports(std::span<const NodeSupport> nodes, std::span<const TetSupport> tets,
                    double ratio);

  const SparseMatrix& matrix() const { return a_; }
  // Index into matrix().valuePtr() of each DOF's diagonal entry.
  std::span<const int> diagonal_index() const { return diagonal_index_; }

 private:
  SparseMatrix a_;
  // Per element, per block (a, b), per column c of the block: the index of the
  // first of three contiguous row entries. 48 entries per element.
  std::vector<std::uint32_t> block_column_start_;
  std::vector<int> diagonal_index_;
  std::vector<int> fixed_off_diagonal_;  // non-zeros zeroed for fixed DOFs
  std::vector<int> fixed_diagonal_dof_;  // DOFs whose diagonal is set alone
  std::vector<std::uint8_t> fixed_dof_;
  std::vector<Tet> tets_;
  std::vector<double> base_diagonal_;  // add_supports' copy of the diagonal
};

}  // namespace fahr::fem
