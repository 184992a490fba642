// Immutable per-tetrahedron rest data, computed once at set-up.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace fahr::fem {

using Tet = std::array<std::uint32_t, 4>;  // node indices, positive rest volume

// Structure of arrays over the elements of one body.
struct ElementRest {
  std::vector<Tet> tets;
  // Inverse of the rest edge matrix Dm = [X1-X0, X2-X0, X3-X0], 1/m, so the
  // deformation gradient is F = Ds Dm^-1 (geometry::deformation_gradient).
  // The FEM's one copy of it: the shape function gradients derive from it.
  std::vector<Eigen::Matrix3d> dm_inv;
  std::vector<double> volume_m3;  // rest volume, m^3, > 0

  std::size_t size() const { return tets.size(); }
};

// The rest gradients of the linear shape functions, 1/m: column a is
// dN_a/dX. For a = 1..3 they are the rows of Dm^-1; N_0 = 1 - N_1 - N_2 - N_3.
inline Eigen::Matrix<double, 3, 4> shape_gradients(const Eigen::Matrix3d& dm_inv) {
  Eigen::Matrix<double, 3, 4> g;
  g.block<3, 3>(0, 1) = dm_inv.transpose();
  g.col(0) = -(g.col(1) + g.col(2) + g.col(3));
  return g;
}

// Smallest accepted 6 V / L^3 (L the longest edge): a regular tet has
// 6 V / L^3 = 0.71; below 1e-6 Dm^-1 has entries a million times the inverse
// edge length and the element is numerically flat.
inline constexpr double kMinTetShapeQuality = 1e-6;

// Fills `rest` or returns a sentence naming the first bad element or node.
std::string build_element_rest(std::span<const Eigen::Vector3d> rest_positions_m,
                               std::span<const Tet> tets, ElementRest& rest);

}  // namespace fahr::fem
