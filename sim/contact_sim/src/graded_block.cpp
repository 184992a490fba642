// Graded rectilinear grid and its Kuhn tetrahedra.
#include "fahr/contact/sim/graded_block.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <array>
#include <cmath>

namespace fahr::contact::sim {
namespace {

// Coordinates from 0 to `extent`: uniform cells of `fine` up to
// `fine_extent`, then cells growing by `growth` (the last one stretched or
// merged so the grid ends exactly at `extent`).
std::vector<double> graded_axis(double extent, double fine_extent, double fine, double growth) {
  std::vector<double> c{0.0};
  double cell = fine;
  while (c.back() < extent - 1e-12) {
    if (c.back() >= fine_extent - 1e-12) cell *= growth;
    double next = c.back() + cell;
    // A sliver at the end (< half a cell) is merged into this cell.
    if (extent - next < 0.5 * cell) next = extent;
    c.push_back(std::min(next, extent));
  }
  return c;
}

}  // namespace

BlockScene make_graded_block(const GradedBlockSpec& spec) {
  const std::vector<double> half =
      graded_axis(spec.half_width_m, spec.fine_half_width_m, spec.fine_cell_m, spec.growth);
  std::vector<double> xs;
  for (std::size_t i = half.size(); i-- > 1;) xs.push_back(-half[i]);
  xs.insert(xs.end(), half.begin(), half.end());
  const std::vector<double> down =
      graded_axis(spec.depth_m, spec.fine_depth_m, spec.fine_cell_m, spec.growth);
  std::vector<double> ys;
  for (std::size_t i = down.size(); i-- > 0;) ys.push_back(-down[i]);  // bottom (-depth) to top (0)

  const std::size_t nx = xs.size(), ny = ys.size(), nz = xs.size();
  BlockScene scene;
  auto index = [&](std::size_t i, std::size_t j, std::size_t k) {
    return static_cast<std::uint32_t>(i + nx * (j + ny * k));
  };
  scene.mesh.nodes_m.resize(nx * ny * nz);
  for (std::size_t k = 0; k < nz; ++k) {
    for (std::size_t j = 0; j < ny; ++j) {
      for (std::size_t i = 0; i < nx; ++i)
        scene.mesh.nodes_m[index(i, j, k)] = Eigen::Vector3d(xs[i], ys[j], xs[k]);
    }
  }
  // The six paths from corner 000 to 111 along the axes in every order.
  constexpr std::array<std::array<int, 3>, 6> kOrders{
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  for (std::size_t k = 0; k + 1 < nz; ++k) {
    for (std::size_t j = 0; j + 1 < ny; ++j) {
      for (std::size_t i = 0; i + 1 < nx; ++i) {
        for (const auto& order : kOrders) {
          std::array<std::size_t, 3> at{i, j, k};
          fem::Tet tet{};
          tet[0] = index(at[0], at[1], at[2]);
          for (std::size_t s = 0; s < 3; ++s) {
            ++at[static_cast<std::size_t>(order[s])];
            tet[s + 1] = index(at[0], at[1], at[2]);
          }
          const auto& p = scene.mesh.nodes_m;
          const double volume =
              (p[tet[1]] - p[tet[0]]).cross(p[tet[2]] - p[tet[0]]).dot(p[tet[3]] - p[tet[0]]);
          if (volume < 0.0) std::swap(tet[1], tet[2]);  // odd permutations come out inverted
          scene.mesh.tets.push_back(tet);
        }
      }
    }
  }
  for (std::size_t k = 0; k < nz; ++k) {
    for (std::size_t i = 0; i < nx; ++i) {
      scene.fixed_nodes.push_back(index(i, 0, k));
      scene.top_nodes.push_back(index(i, ny - 1, k));
    }
  }
  return scene;
}

}  // namespace fahr::contact::sim
