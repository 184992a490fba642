// Rigid tool shapes of the test scenes and the contact rows they produce
// against tissue spheres (and a rigid plane obstacle), standing in for the
// AIST queries (libs/collision) behind the same ContactRow interface.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "fahr/contact/contact_row.h"

namespace fahr::contact::sim {

struct SphereView {
  std::span<const Eigen::Vector3d> centres_m;      // per sphere, m
  std::span<const double> radii_m;                 // per sphere, m
  std::span<const std::int32_t> compliance_index;  // per sphere: index in W or kNoCompliance
};

// A rigid plane obstacle: points x with (x - point) . outward_normal < 0 are inside.
struct PlaneObstacle {
  std::uint32_t id = 0;
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d outward_normal = Eigen::Vector3d::UnitY();
};

enum class ToolKind : std::uint8_t {
  kFlatPunch,  // cylinder along y, flat bottom face at the tool position
  kBall,       // sphere centred at the tool position
};

struct ToolShape {
  ToolKind kind = ToolKind::kFlatPunch;
  double radius_m = 0.005;  // punch or ball radius, m, > 0
  // Rows within this of touching are reported (candidates), m, >= 0.
  double margin_m = 0.002;
};

// Appends the rows of the tool at `tool_position_m` against every sphere and
// obstacle into `rows` (cleared first; capacity reserved by the caller).
void collect_rows(const ToolShape& tool, const Eigen::Vector3d& tool_position_m,
                  const SphereView& spheres, std::span<const PlaneObstacle> obstacles,
                  std::vector<ContactRow>& rows);

}  // namespace fahr::contact::sim
