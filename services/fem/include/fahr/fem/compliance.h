// Contact compliance W = h^2 J A^-1 J^T of candidate spheres (DESIGN.md,
// "Tissue resistance at 1 kHz"): how far sphere centres move in one step per
// newton of force on them, with the tissue's inertia, damping and stiffness.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "fahr/fem/cholmod_solver.h"
#include "fahr/fem/sphere_links.h"
#include "fahr/fem/warped_factor.h"

namespace fahr::fem {

class ComplianceBlock {
 public:
  // Sizes the right-hand sides for up to max_spheres candidates.
  void reserve(std::size_t dofs, std::size_t max_spheres);
  std::size_t capacity() const { return max_spheres_; }

  // Writes W, (3k x 3k) row-major float, m/N, for the k spheres listed, from
  // `factor` (a factorisation of A = M + h D + h^2 K, kg) with one
  // multi-right-hand-side solve (warped to the current rotations): J has three rows per sphere, holding the
  // weights w_i on the x, y and z DOFs of its free nodes (fixed DOFs do not
  // move). Returns false if k exceeds the capacity, `out` is too small, or
  // the factor is missing. Block (s, t) is the motion of sphere s per unit
  // force on sphere t. No allocation after the first call with this k.
  bool compute(std::span<const std::uint32_t> spheres, const SphereLinks& links,
               std::span<const std::uint8_t> fixed_dof, CholmodSolver& factor, WarpedFactor& warp,
               double time_step_s,
               std::span<float> out);

 private:
  std::size_t dofs_ = 0;
  std::size_t max_spheres_ = 0;
  std::vector<double> rhs_;
  std::vector<double> solution_;
};

}  // namespace fahr::fem
