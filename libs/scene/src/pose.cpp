#include "fahr/scene/pose.h"

#include <numbers>

namespace fahr::scene {

Eigen::Quaterniond quaternion_from_rpy_deg(double roll_deg, double pitch_deg, double yaw_deg) {
  constexpr double kRadPerDeg = std::numbers::pi / 180.0;
  const Eigen::AngleAxisd roll(roll_deg * kRadPerDeg, Eigen::Vector3d::UnitX());
  const Eigen::AngleAxisd pitch(pitch_deg * kRadPerDeg, Eigen::Vector3d::UnitY());
  const Eigen::AngleAxisd yaw(yaw_deg * kRadPerDeg, Eigen::Vector3d::UnitZ());
  // Fixed axes x, y, z applied in that order compose right to left.
  Eigen::Quaterniond q = yaw * pitch * roll;
  q.normalize();
  return q;
}

}  // namespace fahr::scene
