// The rigid tool's proxy: where the tool is in the scene, held back by
// tissue and obstacles while the device moves freely. Translation only comes
// out of the contact solve; the orientation is the device's (the Touch X
// renders no torque, so a rotational coupling could not be felt and would
// only let the drawn blade lag the hand).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace fahr::contact {

struct ToolProxy {
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();             // tool frame origin, world, m
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // world_from_tool, unit
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();           // of the last tick, m/s
};

}  // namespace fahr::contact
