// Triangle surfaces through assimp (OBJ, STL, PLY, and whatever else it
// reads). Polygons are triangulated, points and lines dropped, identical
// positions welded so triangles share vertices.
#pragma once

#include <filesystem>

#include "fahr/geometry/surface_mesh.h"

namespace fahr::geometry {

// scale_to_m converts file units to metres. Throws LoadError naming the file.
SurfaceMesh load_surface(const std::filesystem::path& path, double scale_to_m);

}  // namespace fahr::geometry
