// Small scenes shared by the FEM tests.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "fahr/fem/body.h"
#include "fahr/fem/box_mesh.h"

namespace fahr::fem::test {

// A 30 x 10 x 10 mm bar, cells 3 x 1 x 1 scaled by `refine`, tongue-like
// material, its x = 0 face fixed.
inline BodyMesh bar_mesh(int refine = 2) {
  return make_box_mesh({3 * refine, refine, refine}, Eigen::Vector3d(0.03, 0.01, 0.01));
}

inline std::vector<std::uint32_t> nodes_where(const BodyMesh& mesh, auto predicate) {
  std::vector<std::uint32_t> nodes;
  for (std::size_t i = 0; i < mesh.nodes_m.size(); ++i) {
    if (predicate(mesh.nodes_m[i])) nodes.push_back(static_cast<std::uint32_t>(i));
  }
  return nodes;
}

inline std::vector<std::uint32_t> fixed_x0(const BodyMesh& mesh) {
  return nodes_where(mesh, [](const Eigen::Vector3d& p) { return p.x() < 1e-9; });
}

inline std::unique_ptr<Body> make_body(const BodySettings& settings, const BodyMesh& mesh,
                                       const std::vector<std::uint32_t>& fixed) {
  BodyOrError made = Body::create(settings, mesh.nodes_m, mesh.tets, fixed);
  if (!made.error.empty()) return nullptr;
  return std::move(made.body);
}

inline double max_displacement(const Body& body) {
  double largest = 0.0;
  for (std::uint32_t i = 0; i < body.node_count(); ++i) {
    largest = std::max(largest, (body.position(i) - body.rest_position(i)).norm());
  }
  return largest;
}

inline bool all_finite(const Body& body) {
  for (const double x : body.positions_m()) {
    if (!std::isfinite(x)) return false;
  }
  for (const double v : body.velocities_m_per_s()) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

// Height (y) of the lowest node that is not fixed, m.
inline double lowest_free_node_height(const Body& body) {
  double lowest = std::numeric_limits<double>::infinity();
  for (std::uint32_t n = 0; n < body.node_count(); ++n) {
    if (!body.fixed(n)) lowest = std::min(lowest, body.position(n).y());
  }
  return lowest;
}

}  // namespace fahr::fem::test
