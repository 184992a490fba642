// TetGen text format: "count dim attributes markers", then one line per item;
// '#' starts a comment; indices count from 0 or 1 (the first line says which).
#include "tetgen_reader.h"

#include <Eigen/LU>
#include <fstream>
#include <sstream>

namespace fahr::fem::bench {
namespace {

bool next_line(std::ifstream& in, std::istringstream& line, int& line_number) {
  std::string text;
  while (std::getline(in, text)) {
    ++line_number;
    const auto hash = text.find('#');
    if (hash != std::string::npos) text.resize(hash);
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    line.clear();
    line.str(text);
    return true;
  }
  return false;
}

}  // namespace

std::string read_tetgen(const std::string& stem, BodyMesh& mesh) {
  mesh = BodyMesh{};
  const std::string node_path = stem + ".node";
  const std::string ele_path = stem + ".ele";
  std::ifstream nodes(node_path);
  std::ifstream eles(ele_path);
  if (!nodes) return "cannot open " + node_path;
  if (!eles) return "cannot open " + ele_path;
  std::istringstream line;
  int number = 0;
  std::size_t count = 0;
  int dim = 0;
  if (!next_line(nodes, line, number) || !(line >> count >> dim) || dim != 3) {
    return node_path + ":" + std::to_string(number) + ": expected '<count> 3 ...'";
  }
  std::size_t base = 0;
  for (std::size_t i = 0; i < count; ++i) {
    std::size_t index = 0;
    Eigen::Vector3d p;
    if (!next_line(nodes, line, number) || !(line >> index >> p.x() >> p.y() >> p.z())) {
      return node_path + ":" + std::to_string(number) + ": expected '<index> x y z'";
    }
    if (i == 0) base = index;
    mesh.nodes_m.push_back(p);
  }
  number = 0;
  std::size_t per = 0;
  if (!next_line(eles, line, number) || !(line >> count >> per) || per != 4) {
    return ele_path + ":" + std::to_string(number) + ": expected '<count> 4 ...' (linear tets)";
  }
  for (std::size_t e = 0; e < count; ++e) {
    std::size_t index = 0;
    std::array<std::size_t, 4> n{};
    if (!next_line(eles, line, number) || !(line >> index >> n[0] >> n[1] >> n[2] >> n[3])) {
      return ele_path + ":" + std::to_string(number) + ": expected '<index> n0 n1 n2 n3'";
    }
    Tet tet{};
    for (std::size_t a = 0; a < 4; ++a) {
      if (n[a] < base || n[a] - base >= mesh.nodes_m.size()) {
        return ele_path + ":" + std::to_string(number) + ": node index out of range";
      }
      tet[a] = static_cast<std::uint32_t>(n[a] - base);
    }
    Eigen::Matrix3d dm;
    dm << mesh.nodes_m[tet[1]] - mesh.nodes_m[tet[0]], mesh.nodes_m[tet[2]] - mesh.nodes_m[tet[0]],
        mesh.nodes_m[tet[3]] - mesh.nodes_m[tet[0]];
    if (dm.determinant() < 0.0) std::swap(tet[2], tet[3]);
    mesh.tets.push_back(tet);
  }
  return {};
}

}  // namespace fahr::fem::bench
