// The contact experiments as functions returning numbers, so the tests
// assert on exactly what bench/contact prints (docs/design/experiments.md).
#pragma once

#include <cstdint>

#include "fahr/contact/sim/lockstep_run.h"

namespace fahr::contact::sim {

struct PunchResult {
  double fem_hz = 0.0;
  double punch_radius_m = 0.0;      // a, m
  double effective_radius_m = 0.0;  // a_eff of the node patch, m
  double proxy_depth_m = 0.0;       // delta of the tool at the end, m
  double haptic_force_n = 0.0;      // |F| on the stylus at the end, N
  double boussinesq_n = 0.0;        // 2 a_eff E delta / (1 - nu^2), N
  double fem_static_n = 0.0;        // the FEM alone held at delta, N
  double haptic_error = 0.0;        // (haptic - Boussinesq) / Boussinesq
  double fem_error = 0.0;           // (FEM static - Boussinesq) / Boussinesq
  double haptic_vs_fem = 0.0;       // (haptic - FEM static) / FEM static
  bool finite = true;
};

// The FEM alone (punch nodes prescribed 1 mm down, static): its stiffness, N/m.
double fem_static_stiffness(double punch_radius_m);

// Presses the punch to `depth_m` (device target; the proxy stops a coupling
// stretch short) and holds for 0.6 s of simulated time. fem_static_npm: from
// fem_static_stiffness, for the FEM's own error.
PunchResult run_punch_experiment(double fem_hz, double punch_radius_m, double depth_m,
                                 double fem_static_npm);

struct OvershootResult {
  Method method = Method::kForceAware;
  double limit_n = 0.0;
  double coupling_npm = 0.0;
  double max_commanded_n =
      0.0;  // largest K_c |x_d - p| (force-aware) or |k_p sum d n| (penalty), N
  double max_reaction_lost_n = 0.0;  // largest tissue reaction while lost track, N
  double max_reaction_n = 0.0;       // largest tissue reaction overall, N
  double strain_at_1x =
      0.0;  // largest principal Green strain when the command first reached the limit
  double strain_at_3x = 0.0;         // ... when it reached 3x (or the deepest point)
  double max_gap_error_m = 0.0;      // | |gap| - (F_cmd - L)/K_c - L/K_c | while lost track, m
  double max_reengage_step_n = 0.0;  // largest |dF| per tick within 50 ms of re-engagement, N
  double max_tick_step_n = 0.0;      // largest |dF| per tick of the whole run, N
  double displacement_1s_after_release_m = 0.0;
  double max_penetration_m = 0.0;  // deepest row penetration into the tissue, m
  int max_inverted = 0;
  double max_elastic_energy_j = 0.0;
  double final_elastic_energy_j = 0.0;
  bool finite = true;
  double deepest_device_y_m = 0.0;  // for the penalty run to follow the same path
  std::uint64_t lost_track_ticks = 0;
};

// Force-aware: descend until the commanded force reaches 3x the limit,
// hold 5 s, release. Penalty: the same device path down to device_floor_y_m.
OvershootResult run_overshoot_experiment(Method method, double limit_n, double device_floor_y_m);

struct SmoothnessResult {
  Method method = Method::kForceAware;
  double line_n = 0.0;          // 50 Hz line amplitude of |F|, N
  double mean_force_n = 0.0;    // over the window, N
  double tick_median_us = 0.0;  // response tick wall time over the window, us
  double tick_p99_us = 0.0;
  double mean_sweeps = 0.0;  // PGS sweeps per tick over the window
};

// Steady pressing at 5 mm/s with the FEM at 50 Hz; the window is 1 s.
SmoothnessResult run_smoothness_experiment(Method method);

}  // namespace fahr::contact::sim
