// Poses pushed from a topic, screened and clamped to the workspace.
#include "fahr/device/remote_input_backend.h"

#include <algorithm>

namespace fahr::device {

RemoteInputBackend::RemoteInputBackend(const DeviceModel& model)
    : half_workspace_m_(0.5 * model.workspace_m) {}

bool RemoteInputBackend::push(const DeviceReading& reading) {
  const bool finite = reading.position_m.allFinite() && reading.orientation.coeffs().allFinite() &&
                      reading.linear_velocity_mps.allFinite() &&
                      reading.angular_velocity_radps.allFinite();
  // A zero quaternion is finite but no rotation; 1e-6 is far below any rounding of a unit one.
  constexpr double kMinQuaternionNorm = 1e-6;
  if (!finite || reading.orientation.norm() < kMinQuaternionNorm) {
    ++rejected_non_finite_;
    return false;
  }
  newest_ = reading;
  newest_.orientation.normalize();
  const Vec3 clamped = reading.position_m.cwiseMax(-half_workspace_m_).cwiseMin(half_workspace_m_);
  if (clamped != reading.position_m) {
    ++clamped_;
    newest_.position_m = clamped;
  }
  return true;
}

DeviceReading RemoteInputBackend::read(std::chrono::nanoseconds) {
  return newest_;
}

}  // namespace fahr::device
