// Legacy VTK reader (ASCII, DATASET UNSTRUCTURED_GRID, file versions up to
// 5.1 with its OFFSETS/CONNECTIVITY cells). Cell type 10 (tet) makes the
// mesh; 0-, 1- and 2-D cells are skipped; other 3-D cells are an error.
#pragma once

#include <filesystem>

#include "fahr/geometry/tet_mesh.h"
#include "fahr/geometry/text_source.h"

namespace fahr::geometry {

TetMesh load_vtk(const std::filesystem::path& path, double scale_to_m);
TetMesh parse_vtk(const TextSource& source, double scale_to_m);

}  // namespace fahr::geometry
