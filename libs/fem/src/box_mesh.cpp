// Kuhn subdivision of a regular grid: the 6 tets of a cell are the 6 monotone
// paths from corner (0,0,0) to corner (1,1,1), one per axis permutation.
#include "fahr/fem/box_mesh.h"

#include <Eigen/LU>
#include <utility>

namespace fahr::fem {

BodyMesh make_box_mesh(const std::array<int, 3>& cells, const Eigen::Vector3d& size_m,
                       const Eigen::Vector3d& origin_m) {
  BodyMesh mesh;
  const int nx = cells[0];
  const int ny = cells[1];
  const int nz = cells[2];
  const Eigen::Vector3d step(size_m.x() / nx, size_m.y() / ny, size_m.z() / nz);
  auto index = [&](int i, int j, int k) {
    return static_cast<std::uint32_t>(i + (nx + 1) * (j + (ny + 1) * k));
  };
  mesh.nodes_m.reserve(static_cast<std::size_t>(nx + 1) * static_cast<std::size_t>(ny + 1) *
                       static_cast<std::size_t>(nz + 1));
  for (int k = 0; k <= nz; ++k) {
    for (int j = 0; j <= ny; ++j) {
      for (int i = 0; i <= nx; ++i) {
        mesh.nodes_m.push_back(origin_m +
                               Eigen::Vector3d(i * step.x(), j * step.y(), k * step.z()));
      }
    }
  }
  static constexpr std::array<std::array<int, 3>, 6> kPermutations = {
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  mesh.tets.reserve(6 * static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) *
                    static_cast<std::size_t>(nz));
  for (int k = 0; k < nz; ++k) {
    for (int j = 0; j < ny; ++j) {
      for (int i = 0; i < nx; ++i) {
        for (const auto& axes : kPermutations) {
          std::array<int, 3> corner = {i, j, k};
          Tet tet{};
          tet[0] = index(corner[0], corner[1], corner[2]);
          for (std::size_t a = 0; a < 3; ++a) {
            ++corner[static_cast<std::size_t>(axes[a])];
            tet[a + 1] = index(corner[0], corner[1], corner[2]);
          }
          // Odd permutations give negative volume: swap two nodes.
          Eigen::Matrix3d dm;
          dm << mesh.nodes_m[tet[1]] - mesh.nodes_m[tet[0]],
              mesh.nodes_m[tet[2]] - mesh.nodes_m[tet[0]],
              mesh.nodes_m[tet[3]] - mesh.nodes_m[tet[0]];
          if (dm.determinant() < 0.0) std::swap(tet[2], tet[3]);
          mesh.tets.push_back(tet);
        }
      }
    }
  }
  return mesh;
}

}  // namespace fahr::fem
