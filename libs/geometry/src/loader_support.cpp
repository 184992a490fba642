// Shared checks of the tet-mesh loaders.
#include "loader_support.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "fahr/geometry/load_error.h"

namespace fahr::geometry::detail {
namespace {

std::string format_double(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.6g", value);
  return buffer;
}

}  // namespace

void check_scale(double scale_to_m, std::string_view file) {
  if (!(scale_to_m > 0.0) || !std::isfinite(scale_to_m)) {
    throw LoadError(file, 0,
                    "scale to metres must be finite and > 0, got " + format_double(scale_to_m));
  }
}

Eigen::Vector3d read_position(TokenReader& reader, double scale_to_m, const std::string& what) {
  Eigen::Vector3d x;
  int line = 0;
  for (int axis = 0; axis < 3; ++axis) {
    constexpr const char* kAxes = "xyz";
    const std::string field = std::string(1, kAxes[axis]) + " of " + what;
    Token token;
    if (reader.peek(token)) {
      line = token.line;
    }
    x[axis] = reader.expect_finite(field) * scale_to_m;
  }
  if (!x.allFinite()) {
    reader.fail(line, what + ": coordinates overflow when scaled to metres");
  }
  return x;
}

void check_tet_volume(const std::vector<Eigen::Vector3d>& nodes, const Tet& tet,
                      const TokenReader& reader, int line, const std::string& what) {
  const Eigen::Vector3d& x0 = nodes[tet[0]];
  const Eigen::Vector3d& x1 = nodes[tet[1]];
  const Eigen::Vector3d& x2 = nodes[tet[2]];
  const Eigen::Vector3d& x3 = nodes[tet[3]];
  const double volume = signed_volume(x0, x1, x2, x3);
  if (volume <= 0.0 || is_flat_volume(volume, x0, x1, x2, x3)) {
    reader.fail(line, what + ": non-positive volume " + format_double(volume) +
                          " m^3 (inverted or flat tetrahedron)");
  }
}

TetMesh make_tet_mesh(std::vector<Eigen::Vector3d> nodes, std::vector<Tet> tets,
                      std::string_view file) {
  if (tets.empty()) {
    throw LoadError(file, 0, "no tetrahedra in the mesh");
  }
  try {
    return TetMesh(std::move(nodes), std::move(tets));
  } catch (const std::invalid_argument& e) {
    throw LoadError(file, 0, e.what());
  }
}

std::int64_t read_count(TokenReader& reader, const std::string& what) {
  Token token;
  int line = reader.line();
  if (reader.peek(token)) {
    line = token.line;
  }
  const std::int64_t count = reader.expect_int(what);
  if (count < 0 || count > std::numeric_limits<Index>::max()) {
    reader.fail(line, what + " " + std::to_string(count) + " out of range [0, 2^31)");
  }
  return count;
}

}  // namespace fahr::geometry::detail
