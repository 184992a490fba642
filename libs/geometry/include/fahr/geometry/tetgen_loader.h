// TetGen .node/.ele(/.face) reader. Node numbering follows the first index of
// the .node file (0 or 1); attributes are skipped, .face markers are kept.
#pragma once

#include <filesystem>

#include "fahr/geometry/tet_mesh.h"
#include "fahr/geometry/text_source.h"

namespace fahr::geometry {

// path: the .node or .ele file, or their common stem ("tongue.1"); the .face
// file is read when it exists. scale_to_m converts file units to metres
// (0.001 for mm). Throws LoadError naming file, line and node/tet.
TetMesh load_tetgen(const std::filesystem::path& path, double scale_to_m);

// The same from memory; face may have empty text to mean "no .face".
TetMesh parse_tetgen(const TextSource& node, const TextSource& ele, const TextSource& face,
                     double scale_to_m);

}  // namespace fahr::geometry
