// Writers with fixed formatting: coordinates "%.4f" mm (0.1 um), indices as integers.
#include "fahr/scenegen/mesh_writers.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

namespace fahr::scenegen {
namespace {

constexpr double kQuantumMm = 1e-4;  // matches the four decimals written

void write_header(std::ostream& out, const std::string& header) {
  std::istringstream lines(header);
  std::string line;
  while (std::getline(lines, line)) out << "# " << line << "\n";
}

bool save(const std::string& path, const std::string& text, std::string& error) {
  std::ofstream file(path, std::ios::binary);
  file << text;
  file.close();
  if (!file) {
    error = path + ": cannot write";
    return false;
  }
  return true;
}

std::string format_point(const Vec3& p) {
  return format_mm(p.x()) + " " + format_mm(p.y()) + " " + format_mm(p.z());
}

}  // namespace

std::string format_mm(double value) {
  double rounded = std::round(value / kQuantumMm) * kQuantumMm;
  if (rounded == 0.0) rounded = 0.0;  // turns -0 into +0
  char buffer[48];
  std::snprintf(buffer, sizeof(buffer), "%.4f", rounded);
  return buffer;
}

TriangleMesh as_written(const TriangleMesh& mesh) {
  TriangleMesh rounded = mesh;
  for (auto& v : rounded.vertices) {
    for (int k = 0; k < 3; ++k) v[k] = std::stod(format_mm(v[k]));
  }
  return rounded;
}

bool write_tetgen(const MeshedSolid& mesh, const std::string& stem, const std::string& header,
                  std::string& error) {
  std::ostringstream node;
  write_header(node, header);
  node << mesh.nodes.size() << " 3 0 0\n";
  for (size_t i = 0; i < mesh.nodes.size(); ++i) {
    node << i << " " << format_point(mesh.nodes[i]) << "\n";
  }
  std::ostringstream ele;
  write_header(ele, header);
  ele << mesh.tets.size() << " 4 0\n";
  for (size_t i = 0; i < mesh.tets.size(); ++i) {
    const auto& t = mesh.tets[i];
    ele << i << " " << t[0] << " " << t[1] << " " << t[2] << " " << t[3] << "\n";
  }
  std::ostringstream face;
  write_header(face, header);
  face << mesh.boundary.size() << " 0\n";
  for (size_t i = 0; i < mesh.boundary.size(); ++i) {
    const auto& f = mesh.boundary[i];
    face << i << " " << f[0] << " " << f[1] << " " << f[2] << "\n";
  }
  return save(stem + ".node", node.str(), error) && save(stem + ".ele", ele.str(), error) &&
         save(stem + ".face", face.str(), error);
}

bool write_obj(const TriangleMesh& mesh, const std::string& path, const std::string& header,
               std::string& error) {
  std::ostringstream out;
  write_header(out, header);
  for (const auto& v : mesh.vertices) out << "v " << format_point(v) << "\n";
  for (const auto& t : mesh.triangles) {
    out << "f " << t[0] + 1 << " " << t[1] + 1 << " " << t[2] + 1 << "\n";
  }
  return save(path, out.str(), error);
}

bool write_index_list(const std::vector<int>& indices, const std::string& path,
                      const std::string& header, std::string& error) {
  std::ostringstream out;
  write_header(out, header);
  for (const int i : indices) out << i << "\n";
  return save(path, out.str(), error);
}

}  // namespace fahr::scenegen
