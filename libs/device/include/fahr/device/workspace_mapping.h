// Maps the device frame to the scene's world frame: a stylus at device
// position p is at world_from_device * (motion_scale p). Forces go back by
// the rotation only (no force scaling: the device's limits are in its own
// newtons).
#pragma once

#include "fahr/device/types.h"

namespace fahr::device {

struct WorkspaceMapping {
  Vec3 translation_m = Vec3::Zero();  // world_from_device translation, m
  Quat rotation = Quat::Identity();   // world_from_device rotation, unit
  double motion_scale = 1.0;          // (0, 100]

  bool is_identity() const;
  // Fills the pose fields of `pose` from a device-frame reading.
  void to_world(const DeviceReading& reading, DevicePoseSample& pose) const;
  Vec3 force_to_device(const Vec3& world_force_n) const;
  // World target to device frame (for scripted trajectories).
  Vec3 position_to_device(const Vec3& world_position_m) const;
  Quat orientation_to_device(const Quat& world_orientation) const;
};

}  // namespace fahr::device
