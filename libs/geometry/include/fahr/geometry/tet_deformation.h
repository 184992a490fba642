// Kinematics of one linear tetrahedron: its edge matrix and its deformation
// gradient. The one definition the FEM, the sphere layout, the collision
// state and the benches share, so every F is the same number.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>

namespace fahr::geometry {

// The edge matrix [x1 - x0, x2 - x0, x3 - x0] of a tet, m: Dm at rest, Ds
// deformed. det = 6 x the signed volume.
inline Eigen::Matrix3d edge_matrix(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                                   const Eigen::Vector3d& x2, const Eigen::Vector3d& x3) {
  Eigen::Matrix3d e;
  e.col(0) = x1 - x0;
  e.col(1) = x2 - x0;
  e.col(2) = x3 - x0;
  return e;
}

// The same from flat positions (x, y, z per node, m; the FEM's layout) and
// the tet's four node indices (any integer type: the FEM's and the mesh's).
template <typename NodeIndex>
Eigen::Matrix3d edge_matrix(const double* positions_m, const std::array<NodeIndex, 4>& tet) {
  const auto node = [positions_m](NodeIndex n) {
    return Eigen::Map<const Eigen::Vector3d>(positions_m + 3 * static_cast<std::size_t>(n));
  };
  const Eigen::Map<const Eigen::Vector3d> x0 = node(tet[0]);
  Eigen::Matrix3d e;
  e.col(0) = node(tet[1]) - x0;
  e.col(1) = node(tet[2]) - x0;
  e.col(2) = node(tet[3]) - x0;
  return e;
}

// The deformation gradient F = Ds Dm^-1 (dimensionless) of a tet at flat
// positions_m, given the inverse of its rest edge matrix (1/m). det F <= 0:
// the tet is flat or inverted.
template <typename NodeIndex>
Eigen::Matrix3d deformation_gradient(const double* positions_m, const std::array<NodeIndex, 4>& tet,
                                     const Eigen::Matrix3d& rest_edge_inverse) {
  return edge_matrix(positions_m, tet) * rest_edge_inverse;
}

}  // namespace fahr::geometry
