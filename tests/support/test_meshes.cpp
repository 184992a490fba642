// Test meshes (see test_meshes.h).
#include "test_meshes.h"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <map>
#include <numbers>

#include "fahr/geometry/tetgen_loader.h"

namespace fahr::test {

geometry::TetMesh block_tet_mesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int n) {
  std::vector<Eigen::Vector3d> x;
  auto id = [n](int i, int j, int k) {
    return static_cast<geometry::Index>(i + (n + 1) * (j + (n + 1) * k));
  };
  for (int k = 0; k <= n; ++k)
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i <= n; ++i) {
        const Eigen::Vector3d u(i, j, k);
        x.push_back(lo + (hi - lo).cwiseProduct(u / n));
      }
  // Kuhn split: the six paths from corner 0 to corner 7 along the axes.
  static constexpr std::array<std::array<int, 3>, 6> kPaths = {
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  std::vector<geometry::Tet> tets;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (const auto& path : kPaths) {
          std::array<int, 3> c{i, j, k};
          geometry::Tet t{};
          t[0] = id(c[0], c[1], c[2]);
          for (int s = 0; s < 3; ++s) {
            ++c[static_cast<std::size_t>(path[static_cast<std::size_t>(s)])];
            t[static_cast<std::size_t>(s) + 1] = id(c[0], c[1], c[2]);
          }
          const Eigen::Vector3d a = x[t[0]];
          if ((x[t[1]] - a).dot((x[t[2]] - a).cross(x[t[3]] - a)) < 0.0) std::swap(t[2], t[3]);
          tets.push_back(t);
        }
  return geometry::TetMesh(std::move(x), std::move(tets));
}

geometry::SurfaceMesh box_surface(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  std::vector<Eigen::Vector3d> v;
  v.reserve(8);
  for (int k = 0; k < 8; ++k)
    v.emplace_back((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z());
  // Two triangles per face, counter-clockwise seen from outside.
  std::vector<geometry::Triangle> t = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6},
                                       {0, 1, 5}, {0, 5, 4}, {2, 6, 7}, {2, 7, 3},
                                       {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
  return geometry::SurfaceMesh(std::move(v), std::move(t));
}

geometry::SurfaceMesh icosphere(const Eigen::Vector3d& centre, double radius, int subdivisions) {
  const double g = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0},
                                    {0, -1, g}, {0, 1, g}, {0, -1, -g}, {0, 1, -g},
                                    {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
  for (auto& p : v) p.normalize();
  std::vector<geometry::Triangle> t = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                       {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                       {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                       {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<int, int>, int> mid;
    auto middle = [&](int a, int b) {
      const auto key = std::minmax(a, b);
      const auto it = mid.find(key);
      if (it != mid.end()) return it->second;
      v.push_back((v[static_cast<std::size_t>(a)] + v[static_cast<std::size_t>(b)]).normalized());
      const int index = static_cast<int>(v.size()) - 1;
      mid[key] = index;
      return index;
    };
    std::vector<geometry::Triangle> next;
    for (const auto& f : t) {
      const int a = middle(f[0], f[1]), b = middle(f[1], f[2]), c = middle(f[2], f[0]);
      next.push_back({f[0], a, c});
      next.push_back({f[1], b, a});
      next.push_back({f[2], c, b});
      next.push_back({a, b, c});
    }
    t = std::move(next);
  }
  for (auto& p : v) p = centre + radius * p;
  return geometry::SurfaceMesh(std::move(v), std::move(t));
}

const geometry::TetMesh& neonatal_tongue() {
  static const geometry::TetMesh mesh =
      geometry::load_tetgen(std::string(FAHR_NEONATAL_DIR) + "/tongue", 0.001);
  return mesh;
}

const sphere_layout::SphereLayout& neonatal_layout() {
  static const sphere_layout::SphereLayout layout =
      sphere_layout::fill_spheres(neonatal_tongue(), sphere_layout::FillSettings{});
  return layout;
}

}  // namespace fahr::test
