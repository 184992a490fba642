// contact_bench property [--runs N] [--seconds S] [--threads T] [--first R]:
// the 10,000 property runs (sim/property_run.h), one table.
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "bench.h"
#include "fahr/contact/sim/property_run.h"

namespace fahr::contact::bench {
namespace {

struct Options {
  int runs = 10000;
  int first = 0;
  double seconds = sim::kPropertyRunSeconds;
  int threads = 2;
};

bool parse(int argc, char** argv, Options& o) {
  for (int i = 0; i < argc; ++i) {
    const bool has_value = i + 1 < argc;
    if (std::strcmp(argv[i], "--runs") == 0 && has_value) {
      o.runs = std::atoi(argv[++i]);
    } else if (std::strcmp(argv[i], "--first") == 0 && has_value) {
      o.first = std::atoi(argv[++i]);
    } else if (std::strcmp(argv[i], "--seconds") == 0 && has_value) {
      o.seconds = std::atof(argv[++i]);
    } else if (std::strcmp(argv[i], "--threads") == 0 && has_value) {
      o.threads = std::atoi(argv[++i]);
    } else {
      std::fprintf(stderr, "contact_bench property: unknown or incomplete option '%s'\n", argv[i]);
      return false;
    }
  }
  if (o.runs < 1 || o.first < 0 || !(o.seconds > 0.0) || o.threads < 1) {
    std::fprintf(
        stderr,
        "contact_bench property: --runs >= 1, --first >= 0, --seconds > 0, --threads >= 1\n");
    return false;
  }
  return true;
}

}  // namespace

int run_property(int argc, char** argv) {
  Options o;
  if (!parse(argc, argv, o)) return 1;
  std::printf(
      "\n== property runs: %d lockstep runs of %.1f s (runs %d-%d), 432-tet block, %d threads ==\n",
      o.runs, o.seconds, o.first, o.first + o.runs - 1, o.threads);
  std::vector<sim::PropertyRunResult> results(static_cast<std::size_t>(o.runs));
  std::atomic<int> next{0};
  std::atomic<bool> setup_failed{false};
  const auto start = std::chrono::steady_clock::now();
  auto worker = [&] {
    std::string error;
    sim::PropertyScenes scenes(error);
    if (!error.empty()) {
      std::fprintf(stderr, "contact_bench property: %s\n", error.c_str());
      setup_failed = true;
      return;
    }
    // Runs are independent (each starts from rest), so the table does not
    // depend on which thread ran which.
    for (int i = next++; i < o.runs; i = next++) {
      results[static_cast<std::size_t>(i)] = sim::run_property(o.first + i, o.seconds, scenes);
    }
  };
  std::vector<std::thread> threads;
  threads.reserve(static_cast<std::size_t>(o.threads));
  for (int t = 0; t < o.threads; ++t) threads.emplace_back(worker);
  for (std::thread& t : threads) t.join();
  const double wall_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (setup_failed) return 1;

  int froze = 0, not_finite = 0, failed = 0;
  double reaction = 0.0, command = 0.0, penetration_m = 0.0, force_only_m = 0.0;
  for (const sim::PropertyRunResult& r : results) {
    froze += r.froze ? 1 : 0;
    not_finite += r.finite ? 0 : 1;
    reaction = std::max(reaction, r.max_reaction_n / r.limit_n);
    command = std::max(command, r.max_command_n / r.limit_n);
    penetration_m = std::max(penetration_m, r.max_persistent_penetration_m);
    force_only_m = std::max(force_only_m, r.max_force_only_penetration_m);
    if (!r.ok() && ++failed <= 10)
      std::printf("run %d (seed %llu): %s\n", r.run, static_cast<unsigned long long>(r.seed),
                  r.failure.c_str());
  }
  std::printf("%7s %7s %16s %15s %18s %19s %5s %7s %8s\n", "runs", "froze", "max reaction/L",
              "max command/L", "max persist. um", "max force-only um", "NaN", "failed", "wall s");
  std::printf("%7d %7d %16.4f %15.4f %18.2f %19.2f %5d %7d %8.1f\n", o.runs, froze, reaction,
              command, 1e6 * penetration_m, 1e6 * force_only_m, not_finite, failed, wall_s);
  std::printf(
      "target: no NaN, command <= L, reaction <= 1.05 L, no active penetration > 10 um kept 3 FEM "
      "steps: %s\n",
      failed == 0 ? "met" : "MISSED");
  return failed == 0 ? 0 : 1;
}

}  // namespace fahr::contact::bench
