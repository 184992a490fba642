// The glottic view: which opening is scored, from which eye, how often.
#pragma once

#include <Eigen/Core>

namespace fahr::scene {

struct GlotticViewSettings {
  // The glottic opening as a disc, world frame: centre (m), unit normal out
  // of the airway, radius (m).
  Eigen::Vector3d opening_centre_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d opening_normal = Eigen::Vector3d::UnitY();
  double opening_radius_m = 0.0;
  // The laryngoscopist's eye in the tool's frame (m): it moves with the blade.
  Eigen::Vector3d eye_in_tool_m = Eigen::Vector3d::Zero();
  // Scores per second, (0, 100].
  double rate_hz = 10.0;
};

}  // namespace fahr::scene
