// The physics targets, on the shared experiments the bench prints.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "fahr/contact/sim/experiments.h"

namespace fahr::contact {
namespace {

// The FEM's own static stiffness under the punch: one solve a process.
double fem_static_npm() {
  static const double npm = sim::fem_static_stiffness(0.005);
  return npm;
}

// One entry per FEM rate, so the shards of the CTest entry share them (the
// 1 kHz run costs as much as the other four tests: it is listed where
// GoogleTest's round-robin puts it beside the shortest).
class FlatPunch : public testing::TestWithParam<double> {};

TEST_P(FlatPunch, MatchesBoussinesq) {
  const double hz = GetParam();
  const sim::PunchResult r = sim::run_punch_experiment(hz, 0.005, 0.001, fem_static_npm());
  EXPECT_TRUE(r.finite);
  EXPECT_LT(std::abs(r.haptic_error), 0.10)
      << hz << " Hz: haptic " << r.haptic_force_n << " N, Boussinesq " << r.boussinesq_n << " N";
  // The solve reproduces the FEM's own static force closely.
  EXPECT_LT(std::abs(r.haptic_vs_fem), 0.03) << hz << " Hz";
}

INSTANTIATE_TEST_SUITE_P(FemRates, FlatPunch, testing::Values(50.0, 1000.0, 200.0),
                         [](const testing::TestParamInfo<double>& param) {
                           return std::to_string(static_cast<int>(param.param)) + "Hz";
                         });

TEST(Physics, OvershootStaysStableAndWithinTheLimit) {
  constexpr double kLimitN = 1.0;
  const sim::OvershootResult r =
      sim::run_overshoot_experiment(sim::Method::kForceAware, kLimitN, 0.0);
  EXPECT_TRUE(r.finite);
  EXPECT_EQ(r.max_inverted, 0);
  EXPECT_GE(r.max_commanded_n, 3.0 * kLimitN);
  EXPECT_GT(r.lost_track_ticks, 5000u);
  EXPECT_LE(r.max_reaction_lost_n, 1.05 * kLimitN);
  EXPECT_LE(r.strain_at_3x, 1.05 * r.strain_at_1x);
  EXPECT_LE(r.max_gap_error_m, 1e-5);
  const double bound = r.coupling_npm * (0.02 * 0.001 + 0.05 * 0.001) + 1.0 * (0.02 + 0.05);
  EXPECT_LE(r.max_reengage_step_n, bound);
  EXPECT_LE(r.displacement_1s_after_release_m, 0.001);
}

TEST(Physics, ComplianceSolveIsSmootherThanTheNaiveLoopAt50Hz) {
  const sim::SmoothnessResult solve = sim::run_smoothness_experiment(sim::Method::kForceAware);
  const sim::SmoothnessResult naive = sim::run_smoothness_experiment(sim::Method::kNaive);
  EXPECT_GE(20.0 * std::log10(naive.line_n / solve.line_n), 20.0);
}

}  // namespace
}  // namespace fahr::contact
