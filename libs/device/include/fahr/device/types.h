// Plain data the gateway library works on: a device reading, a force
// command and the pose sample it publishes. The service main converts them
// to and from the generated msg types, so the library never sees the
// transport. Units are SI unless the name says otherwise (_ns: ns).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <chrono>
#include <cstdint>

namespace fahr::device {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Quat = Eigen::Quaterniond;

// Mirrors msg::DeviceSafetyState (same order, so the main casts by value).
enum class SafetyState : std::uint8_t {
  kForceDisabled = 0,  // no force rendered (start-up, silence ended, fault)
  kEngaging = 1,       // commands arrive, waiting for them to stay small
  kForceEnabled = 2,   // rendering ForceCommands
  kRampingDown = 3,    // ForceCommands silent: force ramps to zero
  kFault = 4,          // hardware or calibration fault
};

// What a back-end reads at one servo tick, in the device frame.
struct DeviceReading {
  Vec3 position_m = Vec3::Zero();           // stylus tip, device frame, m, within the workspace box
  Quat orientation = Quat::Identity();      // device_from_stylus, unit
  Vec3 linear_velocity_mps = Vec3::Zero();  // m/s, device frame
  Vec3 angular_velocity_radps = Vec3::Zero();  // rad/s, device frame
  std::uint32_t buttons = 0;                   // bit i: button i pressed
  bool fault = false;  // hardware or calibration fault reported by the back-end
};

// A ForceCommand as the gateway consumes it (world frame).
struct ForceCommandSample {
  std::uint64_t answered_pose_seq = 0;      // header.seq of the DevicePose answered, >= 1
  Vec3 answered_position_m = Vec3::Zero();  // x_k, m
  Vec3 force_n = Vec3::Zero();              // F_k, N
  Mat3 stiffness_npm = Mat3::Zero();        // K_k, N/m, symmetric positive semi-definite
  Vec3 torque_nm = Vec3::Zero();            // N m: logged, never rendered (3-DoF device)
  // The haptic service is ramping or slewing its force (a lost tissue, a
  // resume: ForceCommand.reason other than FORCE_RENDERED): the gateway
  // bounds its output's change to SafetyConfig::resume_step_n a tick while
  // such a command is in use, whatever the commands' arrival jitter.
  bool transition = false;
};

// The DevicePose the gateway publishes for one tick (world frame).
struct DevicePoseSample {
  std::uint64_t seq = 0;                // header.seq the transport stamps: servo_tick + 1
  std::uint64_t servo_tick = 0;         // ticks since start
  std::int64_t device_time_ns = 0;      // gateway clock at the reading (monotonic or simulated), ns
  Vec3 position_m = Vec3::Zero();       // world_from_stylus translation, m
  Quat orientation = Quat::Identity();  // world_from_stylus rotation, unit
  Vec3 linear_velocity_mps = Vec3::Zero();     // world frame, m/s
  Vec3 angular_velocity_radps = Vec3::Zero();  // world frame, rad/s
  std::uint32_t buttons = 0;
  double renderable_force_n = 0.0;       // N, [0, peak force]: what the device can render now
  double max_stiffness_npm = 0.0;        // N/m, > 0
  Vec3 rendered_force_n = Vec3::Zero();  // N, world frame, |.| <= renderable_force_n
  Vec3 logged_torque_nm = Vec3::Zero();  // N m, from the active command; not rendered
  SafetyState safety_state = SafetyState::kForceDisabled;
};

}  // namespace fahr::device
