// Principal Green strain and inversion counts over a body's elements.
#include "fahr/fem/strain.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>

#include "fahr/geometry/tet_deformation.h"

namespace fahr::fem {

double principal_green_strain(const Eigen::Matrix3d& deformation_gradient) {
  const Eigen::Matrix3d& f = deformation_gradient;
  const Eigen::Matrix3d green = 0.5 * (f.transpose() * f - Eigen::Matrix3d::Identity());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(green, Eigen::EigenvaluesOnly);
  return eigen.eigenvalues().cwiseAbs().maxCoeff();
}

double max_principal_green_strain(const ElementRest& rest, std::span<const double> positions_m) {
  double largest = 0.0;
  for (std::size_t e = 0; e < rest.size(); ++e) {
    const Eigen::Matrix3d f =
        geometry::deformation_gradient(positions_m.data(), rest.tets[e], rest.dm_inv[e]);
    largest = std::max(largest, principal_green_strain(f));
  }
  return largest;
}

int inverted_element_count(const ElementRest& rest, std::span<const double> positions_m) {
  int inverted = 0;
  for (std::size_t e = 0; e < rest.size(); ++e) {
    const Eigen::Matrix3d f =
        geometry::deformation_gradient(positions_m.data(), rest.tets[e], rest.dm_inv[e]);
    if (f.determinant() <= 0.0) ++inverted;
  }
  return inverted;
}

}  // namespace fahr::fem
