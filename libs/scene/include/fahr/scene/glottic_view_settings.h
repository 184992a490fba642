// The glottic view: which opening is scored, from which eye, how often.
#pragma once

#include <Eigen/Core>

namespace fahr::scene {

struct GlotticViewSettings {
  // The glottic opening, world frame: centre (m), unit normal out of the
  // airway, radius (m); a disc, or an ellipse whose radius lies along
  // opening_major_axis with opening_minor_radius_m across it (0: a disc).
  Eigen::Vector3d opening_centre_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d opening_normal = Eigen::Vector3d::UnitY();
  double opening_radius_m = 0.0;
  Eigen::Vector3d opening_major_axis = Eigen::Vector3d::Zero();
  double opening_minor_radius_m = 0.0;
  // The laryngoscopist's eye in the tool's frame (m): it moves with the blade.
  Eigen::Vector3d eye_in_tool_m = Eigen::Vector3d::Zero();
  // Scores per second, (0, 100].
  double rate_hz = 10.0;
};

}  // namespace fahr::scene
