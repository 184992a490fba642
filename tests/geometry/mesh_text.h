// Writers of small text meshes in every format the loaders read, so loader
// tests round-trip a mesh built by the test instead of trusting fixtures.
#pragma once

#include <string>

#include "fahr/geometry/tet_mesh.h"

namespace fahr::geometry::test {

// Node positions are written divided by `unit_m` (0.001 writes millimetres).
std::string tetgen_node_text(const TetMesh& mesh, int first_index, double unit_m);
std::string tetgen_ele_text(const TetMesh& mesh, int first_index);
std::string gmsh_v1_text(const TetMesh& mesh, double unit_m);
std::string gmsh_v2_text(const TetMesh& mesh, double unit_m);
std::string gmsh_v41_text(const TetMesh& mesh, double unit_m);
std::string vtk_text(const TetMesh& mesh, double unit_m);
std::string vtk51_text(const TetMesh& mesh, double unit_m);

}  // namespace fahr::geometry::test
