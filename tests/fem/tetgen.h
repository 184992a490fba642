// TetGen files for the FEM tests: .node/.ele into a BodyMesh, and the
// boundary triangles of a .face file.
#pragma once

#include <Eigen/Core>
#include <Eigen/LU>
#include <array>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "fahr/fem/box_mesh.h"

namespace fahr::fem::test {

// The next line that is not blank once '#' comments are cut, into `line`.
inline bool next_tetgen_line(std::ifstream& in, std::istringstream& line) {
  std::string text;
  while (std::getline(in, text)) {
    const auto hash = text.find('#');
    if (hash != std::string::npos) text.resize(hash);
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    line.clear();
    line.str(text);
    return true;
  }
  return false;
}

// Minimal TetGen reader for the FEM tests (libs/geometry's loader builds a
// TetMesh, which the FEM tests do not need):
// .node "count dim attrs markers" then "index x y z ..."; .ele "count 4 attrs"
// then "index n0 n1 n2 n3". '#' starts a comment.
inline bool read_tetgen(const std::string& stem, BodyMesh& mesh, std::string& error) {
  std::ifstream node_file(stem + ".node");
  std::ifstream ele_file(stem + ".ele");
  if (!node_file || !ele_file) {
    error = "cannot open " + stem + ".node/.ele";
    return false;
  }
  std::istringstream line;
  std::size_t count = 0;
  int dim = 0;
  if (!next_tetgen_line(node_file, line) || !(line >> count >> dim) || dim != 3) {
    error = stem + ".node: bad header";
    return false;
  }
  std::size_t base = 0;
  for (std::size_t i = 0; i < count; ++i) {
    std::size_t index = 0;
    Eigen::Vector3d p;
    if (!next_tetgen_line(node_file, line) || !(line >> index >> p.x() >> p.y() >> p.z())) {
      error = stem + ".node: bad node line " + std::to_string(i + 2);
      return false;
    }
    if (i == 0) base = index;  // TetGen files count from 0 or 1
    mesh.nodes_m.push_back(p);
  }
  std::size_t per = 0;
  if (!next_tetgen_line(ele_file, line) || !(line >> count >> per) || per != 4) {
    error = stem + ".ele: bad header";
    return false;
  }
  for (std::size_t e = 0; e < count; ++e) {
    std::size_t index = 0;
    std::array<std::size_t, 4> n{};
    if (!next_tetgen_line(ele_file, line) || !(line >> index >> n[0] >> n[1] >> n[2] >> n[3])) {
      error = stem + ".ele: bad element line " + std::to_string(e + 2);
      return false;
    }
    Tet tet{};
    for (std::size_t a = 0; a < 4; ++a) tet[a] = static_cast<std::uint32_t>(n[a] - base);
    // TetGen orders nodes with negative orientation in our convention for
    // some files: fix the sign so that the rest volume is positive.
    Eigen::Matrix3d dm;
    dm << mesh.nodes_m[tet[1]] - mesh.nodes_m[tet[0]], mesh.nodes_m[tet[2]] - mesh.nodes_m[tet[0]],
        mesh.nodes_m[tet[3]] - mesh.nodes_m[tet[0]];
    if (dm.determinant() < 0.0) std::swap(tet[2], tet[3]);
    mesh.tets.push_back(tet);
  }
  return true;
}

// The triangles of `stem`.face, node indices from the base the .node file
// uses (`base`: its first index). Empty with `error` set on failure.
inline std::vector<std::array<std::uint32_t, 3>> read_tetgen_faces(const std::string& stem,
                                                                   std::size_t base,
                                                                   std::string& error) {
  std::vector<std::array<std::uint32_t, 3>> faces;
  std::ifstream file(stem + ".face");
  std::istringstream line;
  std::size_t count = 0;
  if (!file || !next_tetgen_line(file, line) || !(line >> count)) {
    error = "cannot read " + stem + ".face";
    return faces;
  }
  for (std::size_t f = 0; f < count; ++f) {
    std::size_t index = 0;
    std::array<std::size_t, 3> n{};
    if (!next_tetgen_line(file, line) || !(line >> index >> n[0] >> n[1] >> n[2])) {
      error = stem + ".face: bad line " + std::to_string(f + 2);
      faces.clear();
      return faces;
    }
    faces.push_back({static_cast<std::uint32_t>(n[0] - base),
                     static_cast<std::uint32_t>(n[1] - base),
                     static_cast<std::uint32_t>(n[2] - base)});
  }
  return faces;
}

}  // namespace fahr::fem::test
