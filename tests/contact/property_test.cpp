// Property runs: 1,000 lockstep runs of 2 s on the 432-tet block
// with random, bounded device trajectories (fixed seeds, sim/property_run.h).
// Never NaN, never a force above the limit (ForceCommand and tissue
// reaction), never a persistent penetration of an active constraint. The
// runs come in blocks so CTest can shard them over the cores.
#include <gtest/gtest.h>

#include <cstdio>

#include "fahr/contact/sim/property_run.h"

namespace fahr::contact {
namespace {

constexpr int kRuns = 1000;
constexpr int kBlocks = 10;
constexpr int kRunsPerBlock = kRuns / kBlocks;

class Property : public ::testing::TestWithParam<int> {};

TEST_P(Property, RandomTrajectoriesStaySafe) {
  std::string error;
  sim::PropertyScenes scenes(error);
  ASSERT_TRUE(error.empty()) << error;
  int failures = 0, froze = 0;
  double worst_reaction = 0.0, worst_command = 0.0, worst_penetration_m = 0.0;
  const int first = GetParam() * kRunsPerBlock;
  for (int run = first; run < first + kRunsPerBlock; ++run) {
    const sim::PropertyRunResult r = sim::run_property(run, sim::kPropertyRunSeconds, scenes);
    froze += r.froze ? 1 : 0;
    worst_reaction = std::max(worst_reaction, r.max_reaction_n / r.limit_n);
    worst_command = std::max(worst_command, r.max_command_n / r.limit_n);
    worst_penetration_m = std::max(worst_penetration_m, r.max_persistent_penetration_m);
    if (!r.ok()) {
      ++failures;
      ADD_FAILURE() << "run " << run << " (seed " << r.seed << ") broke a property: " << r.failure;
      if (failures > 5) break;
    }
  }
  EXPECT_EQ(failures, 0);
  // The runs exercise the decision, not only free motion.
  EXPECT_GT(froze, kRunsPerBlock / 10);
  std::printf(
      "runs %d-%d: %d lost track at least once; max reaction/limit %.4f, max command/limit %.4f, "
      "max persistent penetration %.2f um\n",
      first, first + kRunsPerBlock - 1, froze, worst_reaction, worst_command,
      1e6 * worst_penetration_m);
}

INSTANTIATE_TEST_SUITE_P(Blocks, Property, ::testing::Range(0, kBlocks));

}  // namespace
}  // namespace fahr::contact
