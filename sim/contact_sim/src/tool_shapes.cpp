// Closest-feature rows of a flat punch or a ball against spheres and planes.
#include "fahr/contact/sim/tool_shapes.h"

namespace fahr::contact::sim {
namespace {

// A ball and a sphere closer than this (centre to centre, m) have no
// defined normal; the row is skipped (it cannot happen with a tool radius
// larger than the penetration the solve allows).
constexpr double kMinCentreDistanceM = 1e-9;

void punch_rows(const ToolShape& tool, const Eigen::Vector3d& t, const SphereView& spheres,
                std::vector<ContactRow>& rows) {
  for (std::size_t s = 0; s < spheres.centres_m.size(); ++s) {
    const Eigen::Vector3d& c = spheres.centres_m[s];
    const double rho = Eigen::Vector2d(c.x() - t.x(), c.z() - t.z()).norm();
    if (rho > tool.radius_m) continue;
    ContactRow row;
    row.kind = RowKind::kTissue;
    row.id = static_cast<std::uint32_t>(s);
    row.normal = -Eigen::Vector3d::UnitY();  // from the bottom face down toward the tissue
    row.tool_point_m = Eigen::Vector3d(c.x(), t.y(), c.z());
    row.other_point_m = c;
    row.radius_m = spheres.radii_m[s];
    row.compliance_index = spheres.compliance_index[s];
    if (row.penetration_m() < -tool.margin_m) continue;
    rows.push_back(row);
  }
}

void ball_rows(const ToolShape& tool, const Eigen::Vector3d& t, const SphereView& spheres,
               std::vector<ContactRow>& rows) {
  for (std::size_t s = 0; s < spheres.centres_m.size(); ++s) {
    const Eigen::Vector3d& c = spheres.centres_m[s];
    const Eigen::Vector3d offset = c - t;
    const double distance = offset.norm();
    if (distance < kMinCentreDistanceM) continue;
    if (distance - tool.radius_m - spheres.radii_m[s] > tool.margin_m) continue;
    ContactRow row;
    row.kind = RowKind::kTissue;
    row.id = static_cast<std::uint32_t>(s);
    row.normal = offset / distance;
    row.tool_point_m = t + tool.radius_m * row.normal;
    row.other_point_m = c;
    row.radius_m = spheres.radii_m[s];
    row.compliance_index = spheres.compliance_index[s];
    rows.push_back(row);
  }
}

}  // namespace

void collect_rows(const ToolShape& tool, const Eigen::Vector3d& tool_position_m,
                  const SphereView& spheres, std::span<const PlaneObstacle> obstacles,
                  std::vector<ContactRow>& rows) {
  rows.clear();
  if (tool.kind == ToolKind::kFlatPunch) {
    punch_rows(tool, tool_position_m, spheres, rows);
  } else {
    ball_rows(tool, tool_position_m, spheres, rows);
  }
  for (const PlaneObstacle& plane : obstacles) {
    // The tool point deepest into the plane: the ball's extreme point, or
    // the punch's reference point (its face centre) for the simple scenes.
    const Eigen::Vector3d deepest =
        tool.kind == ToolKind::kBall
            ? Eigen::Vector3d(tool_position_m - tool.radius_m * plane.outward_normal)
            : tool_position_m;
    const double height = (deepest - plane.point_m).dot(plane.outward_normal);
    if (height > tool.margin_m) continue;
    ContactRow row;
    row.kind = RowKind::kObstacle;
    row.id = plane.id;
    row.normal = -plane.outward_normal;
    row.tool_point_m = deepest;
    row.other_point_m = deepest - height * plane.outward_normal;
    rows.push_back(row);
  }
}

}  // namespace fahr::contact::sim
