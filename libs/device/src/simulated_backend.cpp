// The virtual hand: semi-implicit Euler on stylus-plus-hand mass.
#include "fahr/device/simulated_backend.h"

#include <algorithm>

namespace fahr::device {

SimulatedBackend::SimulatedBackend(Trajectory script, const HandImpedance& hand,
                                   const DeviceModel& model, const WorkspaceMapping& mapping,
                                   std::chrono::nanoseconds period)
    : script_(std::move(script)),
      hand_(hand),
      mapping_(mapping),
      half_workspace_m_(0.5 * model.workspace_m),
      period_s_(std::chrono::duration<double>(period).count()) {
  const TrajectoryPoint start = script_.at(std::chrono::duration<double>(0.0));
  position_m_ = mapping_.position_to_device(start.position_m);
  orientation_ = mapping_.orientation_to_device(start.orientation);
}

DeviceReading SimulatedBackend::read(std::chrono::nanoseconds) {
  DeviceReading reading;
  reading.position_m = position_m_;
  reading.orientation = orientation_;
  reading.linear_velocity_mps = velocity_mps_;
  return reading;
}

void SimulatedBackend::apply(const Vec3& force_n) {
  time_s_ += period_s_;
  const TrajectoryPoint target = script_.at(std::chrono::duration<double>(time_s_));
  const Vec3 target_m = mapping_.position_to_device(target.position_m);
  // force_to_device is the rotation back to the device frame.
  const Vec3 target_velocity_mps =
      mapping_.force_to_device(target.velocity_mps) / mapping_.motion_scale;
  const Vec3 hand_force_n = hand_.stiffness_npm * (target_m - position_m_) +
                            hand_.damping_nspm * (target_velocity_mps - velocity_mps_);
  // Semi-implicit (symplectic) Euler: velocity first, then position with the
  // new velocity; stable for these stiffnesses at 1 ms.
  velocity_mps_ += (hand_force_n + force_n) * (period_s_ / hand_.mass_kg);
  position_m_ += velocity_mps_ * period_s_;
  // The device's mechanical stops: the stylus cannot leave the workspace box.
  for (int axis = 0; axis < 3; ++axis) {
    if (position_m_[axis] > half_workspace_m_[axis] ||
        position_m_[axis] < -half_workspace_m_[axis]) {
      position_m_[axis] =
          std::clamp(position_m_[axis], -half_workspace_m_[axis], half_workspace_m_[axis]);
      velocity_mps_[axis] = 0.0;
    }
  }
  orientation_ = mapping_.orientation_to_device(target.orientation);
}

}  // namespace fahr::device
