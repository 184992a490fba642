// The haptic device a scene is run with and the back-end that provides it.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string_view>

#include "fahr/scene/defaults.h"
#include "fahr/scene/pose.h"

namespace fahr::scene {

enum class DeviceBackend {
  kSimulated,    // virtual hand on a scripted trajectory
  kReplay,       // DevicePose stream of a recording
  kRemote,       // poses from a topic (browser mouse device)
  kOpenHaptics,  // Geomagic Touch X through the HD API
};

enum class DeviceModel {
  kTouchX,  // the device service's published Touch X limits
  kCustom,  // every limit given in the scene
};

enum class DeviceScript {
  kIntubation,  // approach, insert, press the tongue, lever, hold, withdraw
  kOvershoot,   // press past the force limit, hold, release
};

std::string_view to_string(DeviceBackend backend);
std::string_view to_string(DeviceModel model);
std::string_view to_string(DeviceScript script);

// Overrides of the model's limits; an empty field keeps the model's value,
// which the device service owns (with its source).
struct DeviceLimits {
  std::optional<double> peak_force_n;          // N, (0, 100]
  std::optional<double> continuous_force_n;    // N, (0, peak]
  std::optional<double> max_stiffness_npm;     // N/m, (0, 1e5]
  std::optional<Eigen::Vector3d> workspace_m;  // box edge lengths, m, (0, 2]
};

struct DeviceSettings {
  DeviceBackend backend = DeviceBackend::kSimulated;
  DeviceModel model = DeviceModel::kTouchX;
  DeviceLimits limits;
  // Index into Scene::bodies of the tool the device drives.
  std::size_t tool_body = 0;
  // Simulated back-end only.
  DeviceScript script = DeviceScript::kIntubation;
  // Replay back-end only: the recording (absolute path).
  std::filesystem::path replay_file;
  // Workspace mapping: stylus pose in the world = world_from_device applied
  // to the device pose with its position multiplied by motion_scale.
  Pose world_from_device;
  double motion_scale = kDefaultMotionScale;  // (0, 100]
};

}  // namespace fahr::scene
