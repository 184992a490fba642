// Extension dispatch of the tet-mesh loaders.
#include "fahr/geometry/tet_mesh_loader.h"

#include "fahr/geometry/gmsh_loader.h"
#include "fahr/geometry/load_error.h"
#include "fahr/geometry/tetgen_loader.h"
#include "fahr/geometry/vtk_loader.h"

namespace fahr::geometry {

TetMesh load_tet_mesh(const std::filesystem::path& path, double scale_to_m) {
  const std::string extension = path.extension().string();
  if (extension == ".msh") {
    return load_gmsh(path, scale_to_m);
  }
  if (extension == ".vtk") {
    return load_vtk(path, scale_to_m);
  }
  if (extension == ".node" || extension == ".ele" || extension == ".face" ||
      std::filesystem::exists(path.string() + ".node")) {
    return load_tetgen(path, scale_to_m);
  }
  throw LoadError(path.string(), 0,
                  "unknown tet-mesh format '" + extension +
                      "' (expected .node/.ele (TetGen), .msh (Gmsh) or .vtk (legacy VTK))");
}

}  // namespace fahr::geometry
