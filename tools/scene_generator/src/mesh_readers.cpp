// Readers for the generator's own output (comments '#', TetGen headers).
#include "fahr/scenegen/mesh_readers.h"

#include <fstream>
#include <sstream>
#include <vector>

namespace fahr::scenegen {
namespace {

// Non-comment, non-empty lines of a file.
bool data_lines(const std::string& path, std::vector<std::string>& lines, std::string& error) {
  std::ifstream file(path);
  if (!file) {
    error = path + ": cannot open";
    return false;
  }
  std::string line;
  while (std::getline(file, line)) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    if (line.find_first_not_of(" \t\r") != std::string::npos) lines.push_back(line);
  }
  return true;
}

}  // namespace

bool read_obj(const std::string& path, TriangleMesh& mesh, std::string& error) {
  std::vector<std::string> lines;
  if (!data_lines(path, lines, error)) return false;
  for (size_t n = 0; n < lines.size(); ++n) {
    std::istringstream in(lines[n]);
    std::string tag;
    in >> tag;
    if (tag == "v") {
      Vec3 p;
      in >> p.x() >> p.y() >> p.z();
      mesh.vertices.push_back(p);
    } else if (tag == "f") {
      std::array<int, 3> t{};
      in >> t[0] >> t[1] >> t[2];
      for (auto& i : t) --i;
      mesh.triangles.push_back(t);
    }
    if (in.fail()) {
      error = path + ": bad line '" + lines[n] + "'";
      return false;
    }
  }
  return true;
}

bool read_tetgen(const std::string& stem, MeshedSolid& mesh, std::string& error) {
  std::vector<std::string> node;
  std::vector<std::string> ele;
  std::vector<std::string> face;
  if (!data_lines(stem + ".node", node, error) || !data_lines(stem + ".ele", ele, error) ||
      !data_lines(stem + ".face", face, error)) {
    return false;
  }
  int index = 0;
  for (size_t n = 1; n < node.size(); ++n) {
    std::istringstream in(node[n]);
    Vec3 p;
    in >> index >> p.x() >> p.y() >> p.z();
    mesh.nodes.push_back(p);
  }
  for (size_t n = 1; n < ele.size(); ++n) {
    std::istringstream in(ele[n]);
    std::array<int, 4> t{};
    in >> index >> t[0] >> t[1] >> t[2] >> t[3];
    mesh.tets.push_back(t);
  }
  for (size_t n = 1; n < face.size(); ++n) {
    std::istringstream in(face[n]);
    std::array<int, 3> f{};
    in >> index >> f[0] >> f[1] >> f[2];
    mesh.boundary.push_back(f);
  }
  return true;
}

}  // namespace fahr::scenegen
