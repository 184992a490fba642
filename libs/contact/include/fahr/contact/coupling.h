// Virtual coupling between the device and the tool proxy (Colgate, Stanley
// and Brown 1995): a spring and a damper, bounded by what the device renders.
#pragma once

#include <Eigen/Core>

namespace fahr::contact {

struct CouplingSettings {
  double stiffness_npm = 400.0;  // K_c, N/m, > 0; clamped to the device's max stiffness
  double damping_nspm = 1.0;     // B, N s/m, >= 0; clamped to max_damping_nspm
  // A damper of B on a 1 kHz loop renders like a spring of B/dt; 2 N s/m
  // (2000 N/m at 1 kHz) stays within the Touch X's ~1.5 kN/m.
  double max_damping_nspm = 2.0;
};

// The coupling of one tick. The proxy is massless and quasi-static: the
// tissue force -N lambda balances K_c (x_d - p) + B (v_d - (p - p_prev)/dt),
// i.e. K_eff (x_t - p) = N lambda with
//   K_eff = K_c + B/dt,   x_t = (K_c x_d + B v_d + (B/dt) p_prev) / K_eff.
struct EffectiveCoupling {
  double stiffness_npm = 0.0;                          // K_c after clamping, N/m
  double damping_nspm = 0.0;                           // B after clamping, N s/m
  double effective_stiffness_npm = 0.0;                // K_eff, N/m
  Eigen::Vector3d target_m = Eigen::Vector3d::Zero();  // x_t, m
};

// max_stiffness_npm: what the device renders stably now (DevicePose), > 0.
// dt_s: tick period, > 0.
EffectiveCoupling effective_coupling(const CouplingSettings& settings, double max_stiffness_npm,
                                     double dt_s, const Eigen::Vector3d& device_m,
                                     const Eigen::Vector3d& device_velocity_mps,
                                     const Eigen::Vector3d& previous_proxy_m);

}  // namespace fahr::contact
