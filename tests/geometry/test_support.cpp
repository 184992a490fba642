// Test helpers: files, error checks, analytic meshes.
#include "test_support.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <map>

namespace fahr::geometry::test {

TempDir::TempDir() {
  static std::atomic<int> counter{0};
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name =
      info != nullptr ? std::string(info->test_suite_name()) + "_" + info->name() : "fahr";
  std::replace(name.begin(), name.end(), '/', '_');
  path_ = std::filesystem::temp_directory_path() / ("fahr_geometry_" + std::to_string(::getpid()) +
                                                    "_" + std::to_string(counter++) + "_" + name);
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

std::filesystem::path TempDir::write(const std::string& name, const std::string& text) const {
  std::filesystem::path file = path_ / name;
  std::ofstream out(file, std::ios::binary);
  out << text;
  return file;
}

void expect_load_error(const std::function<void()>& load, const std::string& file, int line,
                       const std::vector<std::string>& fragments) {
  try {
    load();
    ADD_FAILURE() << "expected a LoadError from " << file;
  } catch (const LoadError& e) {
    const std::string message = e.what();
    const std::string where = line > 0 ? file + ":" + std::to_string(line) + ":" : file + ":";
    EXPECT_NE(message.find(where), std::string::npos)
        << "message '" << message << "' lacks '" << where << "'";
    EXPECT_EQ(e.file(), file);
    if (line > 0) {
      EXPECT_EQ(e.line(), line) << message;
    }
    for (const std::string& fragment : fragments) {
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "message '" << message << "' lacks '" << fragment << "'";
    }
  }
}

TetMesh cube_tets(int n, double edge_m) {
  std::vector<Eigen::Vector3d> nodes;
  const int m = n + 1;
  for (int k = 0; k < m; ++k) {
    for (int j = 0; j < m; ++j) {
      for (int i = 0; i < m; ++i) {
        nodes.emplace_back(i * edge_m, j * edge_m, k * edge_m);
      }
    }
  }
  const auto id = [m](int i, int j, int k) { return static_cast<Index>(i + m * (j + m * k)); };
  constexpr std::array<std::array<int, 3>, 6> kPermutations = {
      {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  std::vector<Tet> tets;
  for (int k = 0; k < n; ++k) {
    for (int j = 0; j < n; ++j) {
      for (int i = 0; i < n; ++i) {
        for (const auto& perm : kPermutations) {
          std::array<int, 3> c = {i, j, k};
          Tet tet{};
          tet[0] = id(c[0], c[1], c[2]);
          for (std::size_t s = 0; s < 3; ++s) {
            ++c[static_cast<std::size_t>(perm[s])];
            tet[s + 1] = id(c[0], c[1], c[2]);
          }
          if (signed_volume(nodes[tet[0]], nodes[tet[1]], nodes[tet[2]], nodes[tet[3]]) < 0.0) {
            std::swap(tet[2], tet[3]);
          }
          tets.push_back(tet);
        }
      }
    }
  }
  return TetMesh(std::move(nodes), std::move(tets));
}

SurfaceMesh icosphere(int levels, double radius_m, const Eigen::Vector3d& centre) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0},
                                    {0, -1, t}, {0, 1, t}, {0, -1, -t}, {0, 1, -t},
                                    {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
  std::vector<Triangle> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                             {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                             {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                             {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& x : v) {
    x.normalize();
  }
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<Index, Index>, Index> midpoints;
    const auto midpoint = [&](Index a, Index b) {
      const auto key = std::minmax(a, b);
      const auto it = midpoints.find(key);
      if (it != midpoints.end()) {
        return it->second;
      }
      v.push_back((v[a] + v[b]).normalized());
      const auto index = static_cast<Index>(v.size() - 1);
      midpoints.emplace(key, index);
      return index;
    };
    std::vector<Triangle> next;
    for (const Triangle& tri : f) {
      const Index ab = midpoint(tri[0], tri[1]);
      const Index bc = midpoint(tri[1], tri[2]);
      const Index ca = midpoint(tri[2], tri[0]);
      next.push_back({tri[0], ab, ca});
      next.push_back({tri[1], bc, ab});
      next.push_back({tri[2], ca, bc});
      next.push_back({ab, bc, ca});
    }
    f = std::move(next);
  }
  for (auto& x : v) {
    x = centre + radius_m * x;
  }
  return SurfaceMesh(std::move(v), std::move(f));
}

SurfaceMesh box_surface(const Eigen::Vector3d& half_extent_m, int n) {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Triangle> triangles;
  std::map<std::array<int, 3>, Index> index;  // integer lattice key, so shared edges share vertices
  const auto vertex = [&](const std::array<int, 3>& key) {
    const auto it = index.find(key);
    if (it != index.end()) {
      return it->second;
    }
    Eigen::Vector3d x;
    for (int a = 0; a < 3; ++a) {
      x[a] = half_extent_m[a] * (2.0 * key[static_cast<std::size_t>(a)] / n - 1.0);
    }
    vertices.push_back(x);
    const auto id = static_cast<Index>(vertices.size() - 1);
    index.emplace(key, id);
    return id;
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3;
    const int w = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          std::array<std::array<int, 3>, 4> quad{};
          const int di[4] = {0, 1, 1, 0};
          const int dj[4] = {0, 0, 1, 1};
          for (int c = 0; c < 4; ++c) {
            quad[static_cast<std::size_t>(c)][static_cast<std::size_t>(axis)] = side * n;
            quad[static_cast<std::size_t>(c)][static_cast<std::size_t>(u)] = i + di[c];
            quad[static_cast<std::size_t>(c)][static_cast<std::size_t>(w)] = j + dj[c];
          }
          // (u, w, axis) is right-handed, so counter-clockwise in (u, w) faces +axis.
          Index q[4];
          for (int c = 0; c < 4; ++c) {
            q[c] = vertex(quad[static_cast<std::size_t>(c)]);
          }
          if (side == 1) {
            triangles.push_back({q[0], q[1], q[2]});
            triangles.push_back({q[0], q[2], q[3]});
          } else {
            triangles.push_back({q[0], q[2], q[1]});
            triangles.push_back({q[0], q[3], q[2]});
          }
        }
      }
    }
  }
  return SurfaceMesh(std::move(vertices), std::move(triangles));
}

}  // namespace fahr::geometry::test
