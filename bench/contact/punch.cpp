// Flat punch against Boussinesq at three FEM rates.
#include <cstdio>

#include "bench.h"
#include "fahr/contact/sim/experiments.h"

namespace fahr::contact::bench {

int run_punch() {
  std::printf(
      "\n== flat punch: F = 2 a E delta / (1 - nu^2), neonatal tongue E = 7740 Pa, nu = 0.45 ==\n");
  std::printf("%8s %7s %9s %10s %10s %10s %10s %9s %9s %9s\n", "FEM Hz", "a mm", "a_eff mm",
              "delta mm", "haptic N", "Bouss. N", "FEM st. N", "hap err", "FEM err", "hap/FEM");
  int failures = 0;
  const double fem_static_npm = sim::fem_static_stiffness(0.005);
  for (const double hz : {50.0, 200.0, 1000.0}) {
    const sim::PunchResult r = sim::run_punch_experiment(hz, 0.005, 0.001, fem_static_npm);
    std::printf("%8.0f %7.2f %9.3f %10.4f %10.5f %10.5f %10.5f %8.1f%% %8.1f%% %8.1f%%\n", r.fem_hz,
                1e3 * r.punch_radius_m, 1e3 * r.effective_radius_m, 1e3 * r.proxy_depth_m,
                r.haptic_force_n, r.boussinesq_n, r.fem_static_n, 100 * r.haptic_error,
                100 * r.fem_error, 100 * r.haptic_vs_fem);
    if (!(r.finite && r.haptic_error < 0.10 && r.haptic_error > -0.10)) ++failures;
  }
  std::printf("target: |haptic err| < 10%% at every rate: %s\n", failures == 0 ? "met" : "MISSED");
  return failures;
}

}  // namespace fahr::contact::bench
