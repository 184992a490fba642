// First-order thermal model of the motor windings: sustained force above the
// continuous limit heats them, and the force the device may render is
// derated towards the continuous limit until they cool down.
//
// Heat follows copper loss, which grows with the current squared, and motor
// current is proportional to force. So the normalised heat state h obeys
//     tau dh/dt = (|F| / F_cont)^2 - h,
// h = 1 being the steady state of rendering exactly the continuous force.
// The renderable force is the peak force while h <= h_start, falls linearly
// to the continuous force at h = 1, and stays there above 1. Rendering at the
// renderable force therefore settles at h = 1 and |F| = F_cont: sustained
// force is derated to the continuous limit, bursts get the peak.
// Integrated exactly for a constant force over one tick (exponential
// update), so any tick length is stable.
#pragma once

#include <chrono>

#include "fahr/device/device_model.h"

namespace fahr::device {

class ThermalModel {
 public:
  explicit ThermalModel(const DeviceModel& model);

  // Force magnitude the device may render now, N, [continuous, peak].
  double renderable_force_n() const { return renderable_n_; }
  // Normalised heat state, >= 0 (1: steady state at the continuous force).
  double heat() const { return heat_; }

  // Advances the state by `dt` with force magnitude `force_n` (N, >= 0)
  // applied throughout. No allocation.
  void update(double force_n, std::chrono::duration<double> dt);

 private:
  double renderable_for(double heat) const;

  double peak_n_;
  double continuous_n_;
  double tau_s_;
  double derate_start_;
  double heat_ = 0.0;
  double renderable_n_;
};

}  // namespace fahr::device
