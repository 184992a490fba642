// Minimal readers for the files the generator writes, for its test and its
// renderer only. The project's real loaders (with error reporting by file,
// line and element) live in libs/geometry.
#pragma once

#include <string>

#include "fahr/scenegen/geometry_types.h"

namespace fahr::scenegen {

bool read_obj(const std::string& path, TriangleMesh& mesh, std::string& error);
bool read_tetgen(const std::string& stem, MeshedSolid& mesh, std::string& error);

}  // namespace fahr::scenegen
