// aist_bench: prints Markdown tables. Sections: coverage, trajectory, sweep
// (default: all), record / replay FILE (replay.cpp: the query alone on
// recorded states, contact hashes), detection (the trajectory with the FEM driven by its boundary
// points' contacts, both detectors judged on the same states). Usage: aist_bench
// [coverage|trajectory|detection|sweep|all] [--scene-dir DIR] [--max-spheres N] [--ticks N]
// [--fem-every K] [--radius-rule volume|stretch] [--skin-mm S] [--anchor-gap-mm G] [--surface-probe
// anchor|face] [--spread W] [--driver-subdivision N] [--sweep-steps N] [--file PATH] [--evict-kb K]
// [--replay-only K] [--replay-passes P] [--markdown [FILE]]
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "fahr/bench_support/results_file.h"
#include "sections.h"

int main(int argc, char** argv) {
  using namespace fahr::aist_bench;
  fahr::bench_support::MarkdownResults results(argc, argv);
  std::string section = "all";
  Options options;
  std::string scene_dir = FAHR_NEONATAL_DIR;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--scene-dir") == 0 && i + 1 < argc) {
      scene_dir = argv[++i];
    } else if (std::strcmp(argv[i], "--max-spheres") == 0 && i + 1 < argc) {
      options.max_spheres = static_cast<std::size_t>(std::stoul(argv[++i]));
    } else if (std::strcmp(argv[i], "--ticks") == 0 && i + 1 < argc) {
      options.ticks = std::stoi(argv[++i]);
    } else if (std::strcmp(argv[i], "--spread") == 0 && i + 1 < argc) {
      options.weight_spread = std::stod(argv[++i]);
    } else if (std::strcmp(argv[i], "--surface-probe") == 0 && i + 1 < argc) {
      const std::string probe = argv[++i];
      if (probe != "anchor" && probe != "face") {
        std::fprintf(stderr, "aist_bench: --surface-probe takes anchor or face, not %s\n",
                     probe.c_str());
        return 2;
      }
      options.surface_probe = probe == "anchor"
                                  ? fahr::collision::QuerySettings::SurfaceProbe::kAnchor
                                  : fahr::collision::QuerySettings::SurfaceProbe::kFacePoint;
    } else if (std::strcmp(argv[i], "--anchor-gap-mm") == 0 && i + 1 < argc) {
      options.anchor_gap_m = 1e-3 * std::stod(argv[++i]);
    } else if (std::strcmp(argv[i], "--skin-mm") == 0 && i + 1 < argc) {
      options.skin_m = 1e-3 * std::stod(argv[++i]);
    } else if (std::strcmp(argv[i], "--hugging-tolerance-mm") == 0 && i + 1 < argc) {
      options.hugging_tolerance_m = 1e-3 * std::stod(argv[++i]);
    } else if (std::strcmp(argv[i], "--hugging-radius") == 0 && i + 1 < argc) {
      options.hugging_radius_fraction = std::stod(argv[++i]);
    } else if (std::strcmp(argv[i], "--approach-mm") == 0 && i + 1 < argc) {
      options.approach_margin_m = 1e-3 * std::stod(argv[++i]);
    } else if (std::strcmp(argv[i], "--anchor") == 0 && i + 1 < argc) {
      options.anchor_depth_factor = std::stod(argv[++i]);
    } else if (std::strcmp(argv[i], "--radius-rule") == 0 && i + 1 < argc) {
      options.stretch_radius = std::strcmp(argv[++i], "stretch") == 0;
    } else if (std::strcmp(argv[i], "--fem-every") == 0 && i + 1 < argc) {
      options.fem_every = std::max(1, std::stoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--file") == 0 && i + 1 < argc) {
      options.file = argv[++i];
    } else if (std::strcmp(argv[i], "--replay-passes") == 0 && i + 1 < argc) {
      options.replay_passes = std::max(1, std::stoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--replay-only") == 0 && i + 1 < argc) {
      options.replay_only = std::stoi(argv[++i]);
    } else if (std::strcmp(argv[i], "--evict-kb") == 0 && i + 1 < argc) {
      options.evict_bytes = static_cast<std::size_t>(std::stoul(argv[++i])) * 1024;
    } else if (std::strcmp(argv[i], "--driver-subdivision") == 0 && i + 1 < argc) {
      options.driver_subdivision = std::stoi(argv[++i]);
      if (options.driver_subdivision < 1) {
        std::fprintf(stderr, "aist_bench: --driver-subdivision must be >= 1\n");
        return 2;
      }
    } else if (std::strcmp(argv[i], "--sweep-steps") == 0 && i + 1 < argc) {
      options.sweep_steps = std::stoi(argv[++i]);
    } else {
      section = argv[i];
    }
  }
  try {
    results.begin("aist-" + section);
    const auto scene = load_scene(0.5e-3, scene_dir);
    std::printf("# AIST benchmark (neonatal scene, Miller 1 blade)\n\n");
    if (scene_dir != FAHR_NEONATAL_DIR) std::printf("scene: %s\n\n", scene_dir.c_str());
    std::printf(
        "tongue: %zu nodes, %zu tets, %zu boundary triangles (mean edge %.2f mm); blade: %zu "
        "triangles\n",
        scene->tongue.node_count(), scene->tongue.tet_count(), scene->boundary.triangle_count(),
        scene->mean_boundary_edge_m * 1e3, scene->blade.triangle_count());
    if (section == "coverage" || section == "all") coverage_table(*scene, scene_dir);
    if (section == "trajectory" || section == "all") trajectory_table(*scene, options);
    if (section == "sweep" || section == "all") sweep_table(*scene, options);
    if (section == "record" || section == "replay") {
      if (options.file.empty()) {
        std::fprintf(stderr, "aist_bench: %s needs --file PATH\n", section.c_str());
        return 2;
      }
      if (section == "record") record_states(*scene, options, options.file);
      if (section == "replay") replay_states(*scene, options, options.file);
    }
    if (section == "detection") {
      options.reference_driven = true;
      trajectory_table(*scene, options);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "aist_bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
