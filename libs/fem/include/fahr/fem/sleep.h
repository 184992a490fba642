// Sleep: a body at rest and untouched stops solving until something wakes it.
#pragma once

namespace fahr::fem {

struct SleepSettings {
  bool enabled = true;
  // Kinetic energy per unit mass below which the body counts as still,
  // J/kg: 5e-9 J/kg is an RMS speed of 0.1 mm/s, invisible at any zoom.
  double kinetic_energy_per_mass_j_per_kg = 5e-9;
  // Residual force |f_elastic + f_gravity + f_external| over the free DOFs,
  // as a fraction of the body's weight m |g| (dimensionless): 1e-3 means the
  // body is within 0.1 % of static equilibrium.
  double residual_force_ratio = 1e-3;
  // Absolute residual force floor, N, used when gravity is zero.
  double residual_force_floor_n = 1e-7;
  // Consecutive quiet steps before sleeping, so a body passing through rest
  // at the turning point of an oscillation does not fall asleep.
  int quiet_steps = 50;
};

class SleepMonitor {
 public:
  // Called after each solved step; returns true when the body falls asleep.
  // `touched`: active or frozen contacts or external forces this step.
  bool update(const SleepSettings& settings, double kinetic_energy_j, double mass_kg,
              double residual_force_n, double weight_n, bool touched);
  void wake();
  bool asleep() const { return asleep_; }

 private:
  int quiet_ = 0;
  bool asleep_ = false;
};

}  // namespace fahr::fem
