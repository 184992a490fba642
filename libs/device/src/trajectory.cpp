// Keyframed hand targets and the two scripts of the neonatal scene.
#include "fahr/device/trajectory.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>
#include <stdexcept>

namespace fahr::device {

namespace {

Quat pitch_about_z(double pitch_deg) {
  return Quat(Eigen::AngleAxisd(pitch_deg * std::numbers::pi / 180.0, Vec3::UnitZ()));
}

Vec3 mm(double x, double y, double z) {
  return Vec3(x, y, z) * 1e-3;
}

}  // namespace

Trajectory::Trajectory(std::vector<Keyframe> keyframes) : keyframes_(std::move(keyframes)) {
  if (keyframes_.empty())
    throw std::invalid_argument("Trajectory: at least one keyframe is needed");
  for (std::size_t i = 1; i < keyframes_.size(); ++i) {
    if (!(keyframes_[i].time_s > keyframes_[i - 1].time_s)) {
      throw std::invalid_argument("Trajectory: keyframe " + std::to_string(i) +
                                  " time_s must increase");
    }
  }
}

std::chrono::duration<double> Trajectory::duration() const {
  return std::chrono::duration<double>(keyframes_.empty() ? 0.0 : keyframes_.back().time_s);
}

TrajectoryPoint Trajectory::at(std::chrono::duration<double> time) const {
  TrajectoryPoint point;
  if (keyframes_.empty()) return point;
  const double t = time.count();
  if (t <= keyframes_.front().time_s) {
    point.position_m = keyframes_.front().tip_m;
    point.orientation = pitch_about_z(keyframes_.front().pitch_deg);
    return point;
  }
  if (t >= keyframes_.back().time_s) {
    point.position_m = keyframes_.back().tip_m;
    point.orientation = pitch_about_z(keyframes_.back().pitch_deg);
    return point;
  }
  // Few keyframes (tens): a linear search is cheaper than anything cleverer.
  std::size_t i = 1;
  while (keyframes_[i].time_s < t) ++i;
  const Keyframe& a = keyframes_[i - 1];
  const Keyframe& b = keyframes_[i];
  const double span = b.time_s - a.time_s;
  const double s = (t - a.time_s) / span;
  // Smoothstep: zero velocity at both keyframes, continuous in between.
  const double blend = s * s * (3.0 - 2.0 * s);
  const double blend_rate = 6.0 * s * (1.0 - s) / span;
  point.position_m = a.tip_m + blend * (b.tip_m - a.tip_m);
  point.velocity_mps = blend_rate * (b.tip_m - a.tip_m);
  point.orientation = pitch_about_z(a.pitch_deg + blend * (b.pitch_deg - a.pitch_deg));
  return point;
}

bool script_by_name(std::string_view name, Script& out) {
  for (std::size_t i = 0; i < std::size(kScriptNames); ++i) {
    if (name == kScriptNames[i]) {
      out = static_cast<Script>(i);
      return true;
    }
  }
  return false;
}

Trajectory script_trajectory(Script script, double peak_force_n, double hand_stiffness_npm,
                             double overshoot_factor) {
  switch (script) {
    case Script::kOvershoot:
      return overshoot_script(peak_force_n, hand_stiffness_npm, overshoot_factor);
    case Script::kIntubation:
      break;
  }
  return intubation_script();
}

// Keyframes are the hand's intention, not where the blade ends up: while
// pressing, the target lies a few millimetres below the pressing pose, so the
// hand spring (400 N/m) leans 1.6-2.4 N into the tongue, within the Touch X's
// continuous force, and the tissue decides where the blade stops.
Trajectory intubation_script() {
  return Trajectory({
      {0.0, mm(12.0, 0.5, 0.0), 0.0},  // initial pose: level on the oral axis, 3 mm before the lips
      {1.0, mm(12.0, 0.5, 0.0), 0.0},  // settle
      {2.0, mm(8.0, 0.5, 0.0), 0.0},   // approach the lips
      {3.5, mm(-15.0, 0.0, 0.0), 4.0},   // insert between the lips, tip over the tongue
      {5.0, mm(-33.0, -0.5, 0.0), 8.0},  // pressing pose (meshes/neonatal/README.md)
      {6.0, mm(-34.0, -4.5, 0.0), 8.0},  // press the tongue down
      {7.5, mm(-35.0, -6.5, 0.0),
       14.0},  // lever: pitch up to lift the tongue and expose the glottis
      {9.5, mm(-35.0, -6.5, 0.0), 14.0},  // hold the view
      {11.0, mm(-15.0, 0.0, 0.0), 4.0},   // withdraw
      {12.5, mm(12.0, 0.5, 0.0), 0.0},    // back out of the mouth
      {13.0, mm(12.0, 0.5, 0.0), 0.0},
  });
}

Trajectory overshoot_script(double peak_force_n, double hand_stiffness_npm,
                            double overshoot_factor) {
  // Depth below the pressing pose at which the hand spring pulls with
  // overshoot_factor * peak force against a blade held at the pressing pose.
  const double depth_m = overshoot_factor * peak_force_n / hand_stiffness_npm;
  const Vec3 press = mm(-33.0, -0.5, 0.0);
  const Vec3 deep = press - Vec3(0.0, depth_m, 0.0);
  return Trajectory({
      {0.0, mm(12.0, 0.5, 0.0), 0.0},
      {1.0, mm(12.0, 0.5, 0.0), 0.0},
      {3.0, mm(-15.0, 0.0, 0.0), 4.0},
      {4.5, press, 8.0},
      {5.5, deep, 8.0},    // push past the limit
      {10.5, deep, 8.0},   // hold 5 s
      {11.5, press, 8.0},  // release
      {13.0, mm(-15.0, 0.0, 0.0), 4.0},
      {14.5, mm(12.0, 0.5, 0.0), 0.0},
  });
}

}  // namespace fahr::device
