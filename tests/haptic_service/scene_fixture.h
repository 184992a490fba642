// The neonatal scene's haptic set-up, built once per test binary (the
// sphere filling and the fields take seconds), and DevicePoses to drive it.
#pragma once

#include <Eigen/Geometry>
#include <memory>

#include "device_pose.h"
#include "fahr/haptic_service/haptic_setup.h"
#include "fahr/scene/load_scene.h"

namespace fahr::haptic_service::test {

struct NeonatalScene {
  std::shared_ptr<const scene::Scene> scene;
  HapticSetup setup;
};

// Loaded on first use, shared by every test of the binary.
const NeonatalScene& neonatal_scene();

// A DevicePose at servo tick `tick` with the stylus at `position_m`, pitched
// `pitch_deg` about +z (as the gateway's scripts hold the blade).
msg::DevicePose device_pose(std::uint64_t tick, const Eigen::Vector3d& position_m,
                            double pitch_deg = 0.0, double renderable_force_n = 7.9);

// The rigid body of one anatomy field, posed as in the scene.
collision::RigidBody rigid_body(const RigidField& field);

}  // namespace fahr::haptic_service::test
