// Clamping of the virtual coupling and its quasi-static target.
#include "fahr/contact/coupling.h"

#include <algorithm>

namespace fahr::contact {

EffectiveCoupling effective_coupling(const CouplingSettings& settings, double max_stiffness_npm,
                                     double dt_s, const Eigen::Vector3d& device_m,
                                     const Eigen::Vector3d& device_velocity_mps,
                                     const Eigen::Vector3d& previous_proxy_m) {
  EffectiveCoupling c;
  // The rendered stiffness is at most K_c (docs/design/force-aware-decision.md):
  // clamping K_c to the device's stable stiffness bounds both the coupling
  // and the ForceCommand's.
  c.stiffness_npm = std::clamp(settings.stiffness_npm, 1e-6, std::max(max_stiffness_npm, 1e-6));
  c.damping_nspm = std::clamp(settings.damping_nspm, 0.0, settings.max_damping_nspm);
  const double damping_per_tick = c.damping_nspm / dt_s;  // B/dt, N/m
  c.effective_stiffness_npm = c.stiffness_npm + damping_per_tick;
  c.target_m = (c.stiffness_npm * device_m + c.damping_nspm * device_velocity_mps +
                damping_per_tick * previous_proxy_m) /
               c.effective_stiffness_npm;
  return c;
}

}  // namespace fahr::contact
