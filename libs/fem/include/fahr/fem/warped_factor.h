// A factorisation of an earlier system matrix, rotated per node into the
// current frame ("stiffness warping", Mueller, Dorsey, McMillan, Jaillet and
// Cutler, "Stable real-time deformations", SCA 2002).
//
// A corotated A = (1 + h alpha) M + s R K0 R^T changes mostly by the
// rotation of the material. With Q_i the rotation of node i since the
// factorisation, A_now ~ Q A_then Q^T (exact for M, which is isotropic per
// node), so A_now^-1 b ~ Q A_then^-1 Q^T b.
//
// Measured: it removes the period-2 oscillation of a never-refreshed factor
// on a bar sagging 45 degrees, but used as the direct solve on the ArtiSynth
// tongue it diverges within 10 steps (node rotations in sliver-rich regions
// feed back into the solve). It is therefore off by default
// (SolverSettings::warp_lagged_factor); as a CG preconditioner it is safe
// (Q A^-1 Q^T stays symmetric positive definite) but did not reduce the
// iteration count in fem_bench.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "fahr/fem/cholmod_solver.h"
#include "fahr/fem/element_rest.h"

namespace fahr::fem {

class WarpedFactor {
 public:
  void resize(std::size_t node_count);
  void set_enabled(bool enabled) { enabled_ = enabled; }
  bool enabled() const { return enabled_; }

  // Node rotations: the polar rotation of the volume-weighted sum of the
  // rotations of the elements around each node. No allocation.
  void update_rotations(const ElementRest& rest,
                        std::span<const Eigen::Matrix3d> element_rotations);
  // The factor was just computed at the current rotations.
  void mark_factorised();

  // x = Q A_then^-1 Q^T b (or A_then^-1 b when disabled). b and x must not
  // alias. No allocation.
  void solve(CholmodSolver& factor, const double* b, double* x);
  // The same for `columns` column-major right-hand sides of length 3 nodes.
  void solve_columns(CholmodSolver& factor, std::span<double> b, std::span<double> x, int columns);

 private:
  void rotate_to_factor_frame(const double* in, double* out) const;   // Q^T
  void rotate_to_current_frame(const double* in, double* out) const;  // Q

  bool enabled_ = true;
  std::vector<Eigen::Matrix3d> sums_;
  std::vector<Eigen::Matrix3d> current_;
  std::vector<Eigen::Matrix3d> at_factor_;
  std::vector<Eigen::Matrix3d> delta_;  // Q_i = current_i at_factor_i^T
  Eigen::VectorXd scratch_;
};

}  // namespace fahr::fem
