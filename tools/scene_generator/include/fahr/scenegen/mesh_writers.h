// Small writers for the standard formats the scene ships in (TetGen
// .node/.ele/.face, Wavefront OBJ, a node list). Fixed number formatting so
// the same mesh always gives the same bytes.
#pragma once

#include <string>
#include <vector>

#include "fahr/scenegen/geometry_types.h"

namespace fahr::scenegen {

// Writes <stem>.node, <stem>.ele and <stem>.face (0-based, mm). Returns false
// and fills `error` (naming the file) when a file cannot be written.
bool write_tetgen(const MeshedSolid& mesh, const std::string& stem, const std::string& header,
                  std::string& error);

bool write_obj(const TriangleMesh& mesh, const std::string& path, const std::string& header,
               std::string& error);

bool write_index_list(const std::vector<int>& indices, const std::string& path,
                      const std::string& header, std::string& error);

// "%.4f" with negative zero written as zero (it would otherwise depend on
// the last rounding step).
std::string format_mm(double value);

// The mesh as write_obj puts it on disk: every coordinate rounded to the
// written 0.1 um. Checks run on this, so a triangle that rounding flattens or
// folds is caught before it is written.
TriangleMesh as_written(const TriangleMesh& mesh);

}  // namespace fahr::scenegen
