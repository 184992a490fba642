// The 50 Hz line of the force with the FEM at 50 Hz: compliance vs naive.
#include <cmath>
#include <cstdio>

#include "bench.h"
#include "fahr/contact/sim/experiments.h"

namespace fahr::contact::bench {

int run_smoothness() {
  const sim::SmoothnessResult solve = sim::run_smoothness_experiment(sim::Method::kForceAware);
  const sim::SmoothnessResult naive = sim::run_smoothness_experiment(sim::Method::kNaive);
  const double db = 20.0 * std::log10(naive.line_n / solve.line_n);
  std::printf(
      "\n== smoothness: 5 mm punch pressed at 5 mm/s, FEM 50 Hz, 1 s window, DFT at 50 Hz ==\n");
  std::printf("%-26s %12s %14s %12s %12s %10s\n", "loop", "mean |F| N", "50 Hz line N",
              "tick med us", "tick p99 us", "sweeps");
  for (const sim::SmoothnessResult* r : {&solve, &naive}) {
    std::printf("%-26s %12.5f %14.3e %12.1f %12.1f %10.1f\n",
                r == &solve ? "compliance solve (29 rows)" : "naive (W = 0, positions)",
                r->mean_force_n, r->line_n, r->tick_median_us, r->tick_p99_us, r->mean_sweeps);
  }
  std::printf("compliance solve below naive by %.1f dB\n", db);
  const bool ok = db >= 20.0;
  std::printf("target: >= 20 dB: %s\n", ok ? "met" : "MISSED");
  return ok ? 0 : 1;
}

}  // namespace fahr::contact::bench
