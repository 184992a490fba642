// The Yeoh stiffening scale of one element.
#include "fahr/fem/compression_stiffening.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

namespace fahr::fem {

double stiffening_scale(const Eigen::Matrix3d& deformation_gradient, double c20_over_c10) {
  if (!(c20_over_c10 > 0.0)) return 1.0;
  const double j = deformation_gradient.determinant();
  // Flat, inverted or broken: the element needs all the push-back there is.
  if (!(j > 0.0) || !std::isfinite(j)) return kMaxStiffeningScale;
  // J^(-2/3) as 1 / cbrt(J)^2: cheaper than pow and exact for cubes.
  const double cube_root = std::cbrt(j);
  const double i1_bar = deformation_gradient.squaredNorm() / (cube_root * cube_root);
  // I1bar >= 3 for every F with J > 0 (the arithmetic-geometric mean of the
  // squared singular values); below 3 is round-off at rest or in rotation.
  const double scale = 1.0 + 2.0 * c20_over_c10 * std::max(0.0, i1_bar - 3.0);
  return std::min(scale, kMaxStiffeningScale);
}

}  // namespace fahr::fem
