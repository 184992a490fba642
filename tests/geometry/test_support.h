// Helpers of the geometry tests: temporary files, error assertions and
// meshes built by the tests themselves (cube tets, icosphere, box).
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "fahr/geometry/load_error.h"
#include "fahr/geometry/surface_mesh.h"
#include "fahr/geometry/tet_mesh.h"

namespace fahr::geometry::test {

// A directory of its own per test, removed at the end.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  std::filesystem::path write(const std::string& name, const std::string& text) const;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// Runs load and expects a LoadError whose message holds "<file>:<line>:" and every fragment.
void expect_load_error(const std::function<void()>& load, const std::string& file, int line,
                       const std::vector<std::string>& fragments);

// An n x n x n grid of cubes of edge `edge_m`, each cut into 6 positive tets (Kuhn subdivision).
TetMesh cube_tets(int n, double edge_m);

// Icosahedron subdivided `levels` times onto a sphere of radius_m around centre.
SurfaceMesh icosphere(int levels, double radius_m,
                      const Eigen::Vector3d& centre = Eigen::Vector3d::Zero());

// Axis-aligned box surface, each face split into 2 n^2 triangles, outward.
SurfaceMesh box_surface(const Eigen::Vector3d& half_extent_m, int n);

}  // namespace fahr::geometry::test
