// Plain mesh containers shared by the scene generator, its renderer and its
// test. Deliberately minimal and apart from libs/ (the generator depends on
// none of them; the loaded, validated mesh is geometry::TetMesh): these only
// carry what the generator writes.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products
#include <array>
#include <vector>

namespace fahr::scenegen {

using Vec3 = Eigen::Vector3d;

// Closed triangle surface. Coordinates in millimetres; triangles index
// `vertices` (0-based) and are counter-clockwise seen from outside.
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

// A solid meshed into tetrahedra, as the generator writes it (TetGen files).
// Coordinates in millimetres; every tet (a, b, c, d) has
// (b - a) . ((c - a) x (d - a)) > 0; `boundary` holds the outward-oriented
// boundary triangles.
struct MeshedSolid {
  std::vector<Vec3> nodes;
  std::vector<std::array<int, 4>> tets;
  std::vector<std::array<int, 3>> boundary;
};

}  // namespace fahr::scenegen
