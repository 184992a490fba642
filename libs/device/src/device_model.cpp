// Device limits. Where the figures come from, and which are estimates, is in
// libs/device/README.md ("Device figures").
#include "fahr/device/device_model.h"

#include <cmath>

namespace fahr::device {

DeviceModel touch_x_model() {
  return DeviceModel{};
}

DeviceModel touch_model() {
  DeviceModel model;
  model.name = "touch";
  model.peak_force_n = 3.3;
  model.continuous_force_n = 0.88;
  model.workspace_m = Vec3(0.160, 0.120, 0.070);
  model.position_resolution_m = 0.055e-3;
  model.max_stiffness_npm = 1020.0;
  return model;
}

namespace {
bool in_range(double value, double low_exclusive, double high_inclusive) {
  return std::isfinite(value) && value > low_exclusive && value <= high_inclusive;
}
}  // namespace

std::string validate(const DeviceModel& model) {
  if (!in_range(model.peak_force_n, 0.0, 100.0)) return "peak_force_n must be in (0, 100] N";
  if (!in_range(model.continuous_force_n, 0.0, model.peak_force_n)) {
    return "continuous_force_n must be in (0, peak_force_n] N";
  }
  for (int axis = 0; axis < 3; ++axis) {
    if (!in_range(model.workspace_m[axis], 0.0, 2.0))
      return "workspace_m edges must be in (0, 2] m";
  }
  if (!in_range(model.position_resolution_m, 0.0, 1e-3))
    return "position_resolution_m must be in (0, 1e-3] m";
  if (!in_range(model.max_stiffness_npm, 0.0, 1e5))
    return "max_stiffness_npm must be in (0, 1e5] N/m";
  if (!in_range(model.thermal_time_constant.count(), 0.0, 3600.0)) {
    return "thermal_time_constant must be in (0, 3600] s";
  }
  if (!(model.thermal_derate_start >= 0.0 && model.thermal_derate_start < 1.0)) {
    return "thermal_derate_start must be in [0, 1)";
  }
  return {};
}

bool model_by_name(std::string_view name, DeviceModel& out) {
  if (name == "touch_x") {
    out = touch_x_model();
    return true;
  }
  if (name == "touch") {
    out = touch_model();
    return true;
  }
  return false;
}

}  // namespace fahr::device
