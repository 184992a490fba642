// What the view needs from a ContactSet: where the blade is, and how hard it
// presses on the tissue. Shared by the visualizer's view service and
// tools/glottic_score, which read the same rows live and from a recording.
#pragma once

#include <Eigen/Geometry>
#include <optional>

#include "contact_set.h"

namespace fahr::glottic_view {

struct BladeFromContacts {
  // The set's world_from_tool; absent when its quaternion is degenerate
  // (norm below 0.5, or not finite: a haptic service with no tool pose yet
  // sends zeros) or its position is not finite.
  std::optional<Eigen::Isometry3d> world_from_tool;
  // |sum of force_n * normal| over the rows that are not the anatomy's
  // (CONTACT_OBSTACLE), N; 0 when not finite.
  double tool_force_n = 0.0;
};

BladeFromContacts blade_from_contacts(const msg::ContactSet& set);

}  // namespace fahr::glottic_view
