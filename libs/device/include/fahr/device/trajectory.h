// Scripted hand targets: keyframes of the blade tip position and pitch,
// joined by smoothstep segments (zero velocity at each keyframe, continuous
// velocity), so the virtual hand moves as a hand does, not in steps.
// Scripts are world-frame (the scene's head frame, meshes/neonatal/README.md)
// and built once; evaluating one allocates nothing.
#pragma once

#include <chrono>
#include <string_view>
#include <vector>

#include "fahr/device/types.h"

namespace fahr::device {

struct Keyframe {
  double time_s = 0.0;        // s since the script started, increasing
  Vec3 tip_m = Vec3::Zero();  // blade tip target, world frame, m
  double pitch_deg = 0.0;     // blade pitch about +z, degrees
};

struct TrajectoryPoint {
  Vec3 position_m = Vec3::Zero();
  Vec3 velocity_mps = Vec3::Zero();
  Quat orientation = Quat::Identity();
};

class Trajectory {
 public:
  Trajectory() = default;
  // Keyframes in increasing time, at least one.
  explicit Trajectory(std::vector<Keyframe> keyframes);

  TrajectoryPoint at(std::chrono::duration<double> time) const;
  std::chrono::duration<double> duration() const;
  const std::vector<Keyframe>& keyframes() const { return keyframes_; }

 private:
  std::vector<Keyframe> keyframes_;
};

enum class Script : std::uint8_t {
  kIntubation,  // approach, insert between the lips, press, lever, hold, withdraw
  kOvershoot,   // press the blade up to 3x the force limit, hold 5 s, release
};

// The names scenes and command lines use, in Script's order.
inline constexpr std::string_view kScriptNames[] = {"intubation", "overshoot"};

bool script_by_name(std::string_view name, Script& out);

// A script's keyframes; the overshoot script's depth comes from the device's
// peak force and the hand's stiffness.
Trajectory script_trajectory(Script script, double peak_force_n, double hand_stiffness_npm,
                             double overshoot_factor = 3.0);

// The neonatal intubation: poses from meshes/neonatal/README.md (initial tip
// (12, 0.5, 0) mm, pressing tip (-33, -0.5, 0) mm pitched 8 degrees).
Trajectory intubation_script();
// Presses from the pressing pose along -y (the blade's underside) to a target
// depth at which the hand spring pulls with `overshoot_factor` times
// `peak_force_n` against anything that stops the blade at the pressing pose;
// holds 5 s and releases.
Trajectory overshoot_script(double peak_force_n, double hand_stiffness_npm,
                            double overshoot_factor = 3.0);

}  // namespace fahr::device
