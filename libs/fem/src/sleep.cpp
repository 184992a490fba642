// Sleep hysteresis: enough consecutive quiet steps, woken at once.
#include "fahr/fem/sleep.h"

#include <algorithm>

namespace fahr::fem {

bool SleepMonitor::update(const SleepSettings& settings, double kinetic_energy_j, double mass_kg,
                          double residual_force_n, double weight_n, bool touched) {
  if (!settings.enabled || touched) {
    quiet_ = 0;
    return false;
  }
  const double force_threshold =
      std::max(settings.residual_force_ratio * weight_n, settings.residual_force_floor_n);
  const bool still = kinetic_energy_j <= settings.kinetic_energy_per_mass_j_per_kg * mass_kg;
  const bool balanced = residual_force_n <= force_threshold;
  quiet_ = still && balanced ? quiet_ + 1 : 0;
  if (quiet_ >= settings.quiet_steps) asleep_ = true;
  return asleep_;
}

void SleepMonitor::wake() {
  asleep_ = false;
  quiet_ = 0;
}

}  // namespace fahr::fem
