// Polar decomposition: Newton's iteration for well-shaped elements, SVD with
// the Irving-Teran-Fedkiw sign fix for flat and inverted ones.
#include "fahr/fem/corotation.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <cmath>

namespace fahr::fem {
namespace {

Eigen::Matrix3d rotation_by_svd(const Eigen::Matrix3d& f) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(f, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d u = svd.matrixU();
  Eigen::Matrix3d v = svd.matrixV();
  // Eigen sorts singular values in decreasing order: column 2 is the smallest,
  // which is the one to negate (Irving et al. 2004, section 5).
  if (u.determinant() < 0.0) u.col(2) = -u.col(2);
  if (v.determinant() < 0.0) v.col(2) = -v.col(2);
  return u * v.transpose();
}

}  // namespace

Corotation rotation_from_deformation(const Eigen::Matrix3d& deformation_gradient) {
  Corotation out;
  const double det = deformation_gradient.determinant();
  out.inverted = !(det > 0.0);
  if (det > kPolarMinDeterminant) {
    // Newton's polar iteration R <- (gamma R + R^-T / gamma) / 2 (Higham
    // 1986). R^-T is the cofactor matrix over the determinant, and the
    // cofactor columns are cross products of R's columns, so a step costs
    // three cross products. The determinant scaling gamma = det^(-1/3) only
    // matters far from a rotation; near one (tissue strain) gamma = 1 keeps
    // the quadratic convergence without a cube root.
    Eigen::Matrix3d r = deformation_gradient;
    double d = det;
    for (int it = 0; it < kPolarMaxIterations; ++it) {
      const double gamma = std::abs(d - 1.0) > kPolarScalingThreshold ? 1.0 / std::cbrt(d) : 1.0;
      Eigen::Matrix3d cofactor;
      cofactor.col(0) = r.col(1).cross(r.col(2));
      cofactor.col(1) = r.col(2).cross(r.col(0));
      cofactor.col(2) = r.col(0).cross(r.col(1));
      const Eigen::Matrix3d next = 0.5 * (gamma * r + cofactor / (gamma * d));
      const double change = (next - r).squaredNorm();
      r = next;
      if (change < kPolarTolerance * kPolarTolerance) {
        out.rotation = r;
        return out;
      }
      d = r.col(0).dot(r.col(1).cross(r.col(2)));
      if (!(d > 0.0)) break;
    }
  }
  out.rotation = rotation_by_svd(deformation_gradient);
  return out;
}

}  // namespace fahr::fem
