// The benchmark's sections; each prints its Markdown table(s).
#pragma once

#include <cstddef>
#include <string>

#include "fahr/collision/sphere_query.h"
#include "fahr/sphere_layout/fill_settings.h"
#include "scene.h"

namespace fahr::aist_bench {

struct Options {
  int ticks = 3000;             // haptic ticks of the trajectory (1 kHz)
  int fem_every = 2;            // haptic ticks per FEM step (FEM at 500 Hz with h = 2 ms)
  double lever_depth_m = 3e-3;  // how far the levering sinks the tip
  int sweep_steps = 200;        // FEM steps per sweep configuration
  double skin_m = 0.0;          // AIST contact skin (QuerySettings::contact_skin_m)
  double weight_spread =
      sphere_layout::FillSettings{}
          .weight_spread;  // FillSettings::weight_spread of the trajectory layout
  // FillSettings of the trajectory layout (defaults: the library's).
  double hugging_tolerance_m = sphere_layout::FillSettings{}.hugging_tolerance_m;
  double hugging_radius_fraction = sphere_layout::FillSettings{}.hugging_radius_fraction;
  double approach_margin_m =
      collision::QuerySettings{}.approach_margin_m;  // QuerySettings of the trajectory
  double anchor_depth_factor = sphere_layout::FillSettings{}.hugging_anchor_depth_factor;
  double anchor_gap_m = sphere_layout::FillSettings{}.anchor_gap_m;  // FillSettings::anchor_gap_m
  std::size_t max_spheres =
      sphere_layout::FillSettings{}
          .max_spheres;  // FillSettings::max_spheres (a finer tongue needs more)
  collision::QuerySettings::SurfaceProbe surface_probe =
      collision::QuerySettings{}.surface_probe;  // --surface-probe anchor|face
  // true (section "detection"): the trajectory's FEM is driven by contacts
  // of its own boundary points (surface_contacts.h) instead of the AIST's,
  // so both detectors are judged on states neither of them made.
  bool reference_driven = false;
  // --driver-subdivision N: segments per boundary face edge of those points
  // (1: the nodes only); also the sweep's reference.
  int driver_subdivision = 1;
  // true (--radius-rule stretch): the trajectory's SphereState uses the
  // smallest-stretch radius rule instead of the volume rule.
  bool stretch_radius = false;
  // record / replay (replay.cpp): the recording's path, and how many bytes
  // the replay writes between queries to evict the core's L2 (--evict-kb).
  std::string file;
  std::size_t evict_bytes = std::size_t{4} << 20;
  int replay_passes = 1;  // --replay-passes P: per tick the least of P passes
  int replay_only = -1;   // --replay-only K: replay only the K-th query variant (for perf), -1 all
};

// Candidate margin of the benchmark's queries, m: the closure's tolerance,
// how far inside the surface the sphere union may sit by construction.
inline constexpr double kCandidateMarginM = 0.25e-3;

// The tongue's layouts, the ArtiSynth tongue's, and the epiglottis's thin
// leaf (scene_dir/epiglottis, when the scene has it).
void coverage_table(const Scene& scene, const std::string& scene_dir);
// What the trajectory, record and replay fill and query with (Options').
sphere_layout::FillSettings trajectory_fill(const Options& options);
collision::QuerySettings trajectory_query(const Options& options);
void trajectory_table(const Scene& scene, const Options& options);
void sweep_table(const Scene& scene, const Options& options);
// Writes the trajectory's blade poses and FEM states to options.file.
void record_states(const Scene& scene, const Options& options, const std::string& path);
// Times the AIST query alone on a recording (replay.cpp) and hashes its contacts.
void replay_states(const Scene& scene, const Options& options, const std::string& path);

}  // namespace fahr::aist_bench
