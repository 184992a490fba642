// Rigid placement of a body in the world frame, and the roll-pitch-yaw
// convention the scene files use.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace fahr::scene {

// world_from_body: x_world = orientation * x_body + position_m.
struct Pose {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();             // m
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // unit
};

// Roll, pitch, yaw in degrees as fixed (extrinsic) rotations about the world
// x, then y, then z axis: R = Rz(yaw) * Ry(pitch) * Rx(roll). Any finite angle.
Eigen::Quaterniond quaternion_from_rpy_deg(double roll_deg, double pitch_deg, double yaw_deg);

}  // namespace fahr::scene
