// The benchmark's sections; each prints its Markdown table(s).
#pragma once

#include "fahr/haptic/fill_settings.h"
#include "scene.h"

namespace fahr::aist_bench {

struct Options {
  int ticks = 3000;            // haptic ticks of the trajectory (1 kHz)
  int fem_every = 2;           // haptic ticks per FEM step (FEM at 500 Hz with h = 2 ms)
  double lever_depth_m = 3e-3; // how far the levering sinks the tip
  int sweep_steps = 200;       // FEM steps per sweep configuration
  double skin_m = 0.0;         // AIST contact skin (QuerySettings::contact_skin_m)
  double weight_spread = haptic::FillSettings{}.weight_spread;  // FillSettings::weight_spread of the trajectory layout
};

// Candidate margin of the benchmark's queries, m: the closure's tolerance,
// how far inside the surface the sphere union may sit by construction.
inline constexpr double kCandidateMarginM = 0.25e-3;

void coverage_table(const Scene& scene);
void trajectory_table(const Scene& scene, const Options& options);
void sweep_table(const Scene& scene, const Options& options);

}  // namespace fahr::aist_bench
