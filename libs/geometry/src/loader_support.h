// Checks and helpers shared by the tet-mesh loaders, so every format reports
// the same errors in the same words.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "fahr/geometry/tet_mesh.h"
#include "token_reader.h"

namespace fahr::geometry::detail {

// Throws LoadError unless scale_to_m is finite and > 0.
void check_scale(double scale_to_m, std::string_view file);

// Reads x y z, scales them, and checks the result is finite; `what` names the node in errors.
Eigen::Vector3d read_position(TokenReader& reader, double scale_to_m, const std::string& what);

// Throws LoadError at `line` when the tet is inverted or flat; `what` names the element.
void check_tet_volume(const std::vector<Eigen::Vector3d>& nodes, const Tet& tet,
                      const TokenReader& reader, int line, const std::string& what);

// Builds the mesh; a structural problem found only on the whole mesh (a face
// shared by three tets) becomes a LoadError naming the file.
TetMesh make_tet_mesh(std::vector<Eigen::Vector3d> nodes, std::vector<Tet> tets,
                      std::string_view file);

// Reads a count from a header: an integer in [0, 2^31).
std::int64_t read_count(TokenReader& reader, const std::string& what);

}  // namespace fahr::geometry::detail
