// Rotation of an element from its deformation gradient, robust to inversion.
#pragma once

#include <Eigen/Core>

namespace fahr::fem {

// Newton's polar iteration R <- (R + R^-T) / 2 stops when the change is
// below this (Frobenius norm; R is dimensionless).
inline constexpr double kPolarTolerance = 1e-12;
// Newton's polar iteration converges quadratically once started; if it has
// not converged in this many steps the SVD path takes over.
inline constexpr int kPolarMaxIterations = 20;
// |det R - 1| above this applies Higham's determinant scaling in a Newton
// step; below it the unscaled step already converges quadratically.
inline constexpr double kPolarScalingThreshold = 0.1;
// det(F) below this uses the SVD path: near and past inversion Newton's
// iteration converges slowly or to the wrong (reflection) branch.
inline constexpr double kPolarMinDeterminant = 0.05;

struct Corotation {
  Eigen::Matrix3d rotation;  // proper rotation, det = +1
  bool inverted = false;     // det(F) <= 0 at this step
};

// R from F = U S V^T with the sign fix of Irving, Teran and Fedkiw,
// "Invertible finite elements for robust simulation of large deformation"
// (SCA 2004): if det U or det V is negative, the column of the smallest
// singular value is negated, so R = U V^T is a rotation and an inverted
// element keeps one negative singular value that its elastic force undoes.
Corotation rotation_from_deformation(const Eigen::Matrix3d& deformation_gradient);

}  // namespace fahr::fem
