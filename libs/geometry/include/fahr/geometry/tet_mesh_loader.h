// One entry point for scene files: picks the tet-mesh loader by extension.
#pragma once

#include <filesystem>

#include "fahr/geometry/tet_mesh.h"

namespace fahr::geometry {

// .node / .ele / .face or an extension-less TetGen stem: TetGen; .msh: Gmsh;
// .vtk: legacy VTK. Anything else: LoadError naming the file.
TetMesh load_tet_mesh(const std::filesystem::path& path, double scale_to_m);

}  // namespace fahr::geometry
