// The limits of a haptic device: what it can push, how far it reaches, how
// finely it measures and how stiff a spring it renders stably. The Touch X
// figures are the defaults; other devices are configurations of the same
// struct (libs/device/README.md, "Device figures": sources and estimates).
#pragma once

#include <string>
#include <string_view>

#include "fahr/device/types.h"

namespace fahr::device {

struct DeviceModel {
  std::string name = "touch_x";
  // Largest force magnitude the motors deliver for a short time, N, (0, 100].
  double peak_force_n = 7.9;
  // Force magnitude the device sustains without overheating, N, (0, peak].
  double continuous_force_n = 1.75;
  // Edge lengths of the usable workspace box, centred on the device origin, m, each (0, 2].
  Vec3 workspace_m = Vec3(0.160, 0.120, 0.120);
  // Smallest position step the encoders resolve, m, (0, 1e-3].
  double position_resolution_m = 0.023e-3;
  // Highest stiffness rendered stably, N/m, (0, 1e5]: the weakest axis.
  double max_stiffness_npm = 1480.0;
  // Thermal time constant of the motor windings, (0, 1 h]; see thermal_model.h.
  std::chrono::duration<double> thermal_time_constant{30.0};
  // Heat state (1 = steady state at the continuous force) below which the
  // full peak force is available, [0, 1).
  double thermal_derate_start = 0.6;
};

// The Geomagic / 3D Systems Touch X (the defaults above).
DeviceModel touch_x_model();
// The smaller Geomagic Touch (ex Phantom Omni); figures are estimates.
DeviceModel touch_model();

// Empty if valid; otherwise names the first bad field and its range.
std::string validate(const DeviceModel& model);

// A model by name ("touch_x", "touch"); false if unknown.
bool model_by_name(std::string_view name, DeviceModel& out);

}  // namespace fahr::device
