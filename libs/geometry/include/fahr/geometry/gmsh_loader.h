// Gmsh .msh reader: format 1 ($NOD/$ELM), 2 ASCII and 4 ASCII (4.0 and 4.1).
// Linear tets (element type 4) make the mesh; points, lines and surface
// elements are skipped; other volume elements are an error. Node tags are
// arbitrary ids: node i of the mesh is the i-th node of the file.
#pragma once

#include <filesystem>

#include "fahr/geometry/tet_mesh.h"
#include "fahr/geometry/text_source.h"

namespace fahr::geometry {

TetMesh load_gmsh(const std::filesystem::path& path, double scale_to_m);
TetMesh parse_gmsh(const TextSource& source, double scale_to_m);

}  // namespace fahr::geometry
