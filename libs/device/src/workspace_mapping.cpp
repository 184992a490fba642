// Device frame to world frame and back.
#include "fahr/device/workspace_mapping.h"

namespace fahr::device {

bool WorkspaceMapping::is_identity() const {
  return translation_m.isZero(0.0) && rotation.w() == 1.0 && rotation.vec().isZero(0.0) &&
         motion_scale == 1.0;
}

void WorkspaceMapping::to_world(const DeviceReading& reading, DevicePoseSample& pose) const {
  pose.buttons = reading.buttons;
  if (is_identity()) {
    // Copy, not compute: replay must reproduce a recording bit for bit.
    pose.position_m = reading.position_m;
    pose.orientation = reading.orientation;
    pose.linear_velocity_mps = reading.linear_velocity_mps;
    pose.angular_velocity_radps = reading.angular_velocity_radps;
    return;
  }
  pose.position_m = rotation * (motion_scale * reading.position_m) + translation_m;
  pose.orientation = rotation * reading.orientation;
  pose.linear_velocity_mps = rotation * (motion_scale * reading.linear_velocity_mps);
  pose.angular_velocity_radps = rotation * reading.angular_velocity_radps;
}

Vec3 WorkspaceMapping::force_to_device(const Vec3& world_force_n) const {
  if (is_identity()) return world_force_n;
  return rotation.conjugate() * world_force_n;
}

Vec3 WorkspaceMapping::position_to_device(const Vec3& world_position_m) const {
  if (is_identity()) return world_position_m;
  return (rotation.conjugate() * (world_position_m - translation_m)) / motion_scale;
}

Quat WorkspaceMapping::orientation_to_device(const Quat& world_orientation) const {
  if (is_identity()) return world_orientation;
  return rotation.conjugate() * world_orientation;
}

}  // namespace fahr::device
