// Rest data of linear tetrahedra: Dm^-1 and volume.
#include "fahr/fem/element_rest.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "fahr/geometry/tet_deformation.h"

namespace fahr::fem {
namespace {

double longest_edge(const std::array<Eigen::Vector3d, 4>& x) {
  double longest = 0.0;
  for (int a = 0; a < 4; ++a) {
    for (int b = a + 1; b < 4; ++b) {
      longest = std::max(longest,
                         (x[static_cast<std::size_t>(a)] - x[static_cast<std::size_t>(b)]).norm());
    }
  }
  return longest;
}

}  // namespace

std::string build_element_rest(std::span<const Eigen::Vector3d> rest_positions_m,
                               std::span<const Tet> tets, ElementRest& rest) {
  rest = ElementRest{};
  rest.tets.assign(tets.begin(), tets.end());
  rest.dm_inv.resize(tets.size());
  rest.volume_m3.resize(tets.size());
  for (std::size_t e = 0; e < tets.size(); ++e) {
    std::array<Eigen::Vector3d, 4> x;
    for (std::size_t a = 0; a < 4; ++a) {
      if (tets[e][a] >= rest_positions_m.size()) {
        return "tet " + std::to_string(e) + " references node " + std::to_string(tets[e][a]) +
               " of " + std::to_string(rest_positions_m.size());
      }
      x[a] = rest_positions_m[tets[e][a]];
      if (!x[a].allFinite()) return "node " + std::to_string(tets[e][a]) + " is not finite";
    }
    const Eigen::Matrix3d dm = geometry::edge_matrix(x[0], x[1], x[2], x[3]);
    const double det = dm.determinant();
    const double edge = longest_edge(x);
    // Inverted (negative) or flat tets are rejected: the corotated force of
    // an element inverted at rest would push it further inside out.
    if (!(edge > 0.0) || det / (edge * edge * edge) < kMinTetShapeQuality) {
      return "tet " + std::to_string(e) +
             " has non-positive or near-zero volume (6V = " + std::to_string(det) + " m^3)";
    }
    rest.volume_m3[e] = det / 6.0;
    rest.dm_inv[e] = dm.inverse();
  }
  return {};
}

}  // namespace fahr::fem
