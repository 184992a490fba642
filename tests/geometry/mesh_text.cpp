// Text writers for the loader round-trip tests. Gmsh node tags are written as
// 100 + 7 i, so the loader's tag mapping is exercised.
#include "mesh_text.h"

#include <cstdio>
#include <sstream>

namespace fahr::geometry::test {
namespace {

long long gmsh_tag(std::size_t node) {
  return 100 + 7 * static_cast<long long>(node);
}

std::string xyz(const Eigen::Vector3d& x, double unit_m) {
  char buffer[96];
  std::snprintf(buffer, sizeof buffer, "%.17g %.17g %.17g", x.x() / unit_m, x.y() / unit_m,
                x.z() / unit_m);
  return buffer;
}

}  // namespace

std::string tetgen_node_text(const TetMesh& mesh, int first_index, double unit_m) {
  std::ostringstream out;
  out << "# written by the fahr geometry tests\n" << mesh.node_count() << "  3  0  0\n";
  for (std::size_t n = 0; n < mesh.node_count(); ++n) {
    out << "  " << n + static_cast<std::size_t>(first_index) << "  "
        << xyz(mesh.rest_positions()[n], unit_m) << "\n";
  }
  return out.str();
}

std::string tetgen_ele_text(const TetMesh& mesh, int first_index) {
  std::ostringstream out;
  out << mesh.tet_count() << "  4  0\n";
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    out << "  " << t + static_cast<std::size_t>(first_index);
    for (Index n : mesh.tets()[t]) {
      out << "  " << n + first_index;
    }
    out << "\n";
  }
  return out.str();
}

std::string gmsh_v1_text(const TetMesh& mesh, double unit_m) {
  std::ostringstream out;
  out << "$NOD\n" << mesh.node_count() << "\n";
  for (std::size_t n = 0; n < mesh.node_count(); ++n) {
    out << gmsh_tag(n) << " " << xyz(mesh.rest_positions()[n], unit_m) << "\n";
  }
  out << "$ENDNOD\n$ELM\n" << mesh.tet_count() + 1 << "\n";
  // A boundary triangle first: surface elements are skipped.
  const Triangle& face = mesh.boundary_faces()[0].nodes;
  out << "1 2 1 1 3 " << gmsh_tag(face[0]) << " " << gmsh_tag(face[1]) << " " << gmsh_tag(face[2])
      << "\n";
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    out << t + 2 << " 4 1 1 4";
    for (Index n : mesh.tets()[t]) {
      out << " " << gmsh_tag(n);
    }
    out << "\n";
  }
  out << "$ENDELM\n";
  return out.str();
}

std::string gmsh_v2_text(const TetMesh& mesh, double unit_m) {
  std::ostringstream out;
  out << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n3 1 "
         "\"tongue\"\n$EndPhysicalNames\n";
  out << "$Nodes\n" << mesh.node_count() << "\n";
  for (std::size_t n = 0; n < mesh.node_count(); ++n) {
    out << gmsh_tag(n) << " " << xyz(mesh.rest_positions()[n], unit_m) << "\n";
  }
  out << "$EndNodes\n$Elements\n" << mesh.tet_count() + 1 << "\n";
  out << "1 15 2 0 1 " << gmsh_tag(0) << "\n";
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    out << t + 2 << " 4 2 1 1";
    for (Index n : mesh.tets()[t]) {
      out << " " << gmsh_tag(n);
    }
    out << "\n";
  }
  out << "$EndElements\n";
  return out.str();
}

std::string gmsh_v41_text(const TetMesh& mesh, double unit_m) {
  std::ostringstream out;
  const std::size_t nodes = mesh.node_count();
  out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  out << "$Entities\n0 0 0 1\n1 0 0 0 1 1 1 0 0\n$EndEntities\n";
  // Two node blocks, so block handling is exercised.
  const std::size_t half = nodes / 2;
  out << "$Nodes\n2 " << nodes << " " << gmsh_tag(0) << " " << gmsh_tag(nodes - 1) << "\n";
  for (int block = 0; block < 2; ++block) {
    const std::size_t begin = block == 0 ? 0 : half;
    const std::size_t end = block == 0 ? half : nodes;
    out << "3 1 0 " << end - begin << "\n";
    for (std::size_t n = begin; n < end; ++n) {
      out << gmsh_tag(n) << "\n";
    }
    for (std::size_t n = begin; n < end; ++n) {
      out << xyz(mesh.rest_positions()[n], unit_m) << "\n";
    }
  }
  out << "$EndNodes\n$Elements\n2 " << mesh.tet_count() + 1 << " 1 " << mesh.tet_count() + 1
      << "\n";
  const Triangle& face = mesh.boundary_faces()[0].nodes;
  out << "2 1 2 1\n1 " << gmsh_tag(face[0]) << " " << gmsh_tag(face[1]) << " " << gmsh_tag(face[2])
      << "\n";
  out << "3 1 4 " << mesh.tet_count() << "\n";
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    out << t + 2;
    for (Index n : mesh.tets()[t]) {
      out << " " << gmsh_tag(n);
    }
    out << "\n";
  }
  out << "$EndElements\n";
  return out.str();
}

std::string vtk_text(const TetMesh& mesh, double unit_m) {
  std::ostringstream out;
  out << "# vtk DataFile Version 3.0\nfahr test mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  out << "POINTS " << mesh.node_count() << " double\n";
  for (std::size_t n = 0; n < mesh.node_count(); ++n) {
    out << xyz(mesh.rest_positions()[n], unit_m) << "\n";
  }
  out << "CELLS " << mesh.tet_count() + 1 << " " << 5 * mesh.tet_count() + 2 << "\n1 0\n";
  for (const Tet& tet : mesh.tets()) {
    out << "4 " << tet[0] << " " << tet[1] << " " << tet[2] << " " << tet[3] << "\n";
  }
  out << "CELL_TYPES " << mesh.tet_count() + 1 << "\n1\n";
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    out << "10\n";
  }
  out << "CELL_DATA " << mesh.tet_count() + 1 << "\nSCALARS region int 1\nLOOKUP_TABLE default\n";
  return out.str();
}

std::string vtk51_text(const TetMesh& mesh, double unit_m) {
  std::ostringstream out;
  out << "# vtk DataFile Version 5.1\nfahr test mesh\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  out << "POINTS " << mesh.node_count() << " double\n";
  for (std::size_t n = 0; n < mesh.node_count(); ++n) {
    out << xyz(mesh.rest_positions()[n], unit_m)
        << " ";  // several points per line, as VTK writes them
    if (n % 3 == 2) {
      out << "\n";
    }
  }
  out << "\nCELLS " << mesh.tet_count() + 1 << " " << 4 * mesh.tet_count()
      << "\nOFFSETS vtktypeint64\n";
  for (std::size_t t = 0; t <= mesh.tet_count(); ++t) {
    out << 4 * t << "\n";
  }
  out << "CONNECTIVITY vtktypeint64\n";
  for (const Tet& tet : mesh.tets()) {
    out << tet[0] << " " << tet[1] << " " << tet[2] << " " << tet[3] << "\n";
  }
  out << "CELL_TYPES " << mesh.tet_count() << "\n";
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    out << "10\n";
  }
  return out.str();
}

}  // namespace fahr::geometry::test
