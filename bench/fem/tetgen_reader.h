// Minimal TetGen .node/.ele reader for the benchmarks (the shared loaders of
// libs/geometry could replace it). Fixes tet orientation to positive volume.
#pragma once

#include <string>

#include "fahr/fem/box_mesh.h"

namespace fahr::fem::bench {

// Reads <stem>.node and <stem>.ele; returns an error naming file and line, or
// empty on success.
std::string read_tetgen(const std::string& stem, BodyMesh& mesh);

}  // namespace fahr::fem::bench
