// Each safety rule against a hostile ForceCommand stream, on a stylus the
// test holds still or moves itself. Simulated time; every tick checked.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "fahr/device/servo_core.h"
#include "test_support.h"

namespace fahr::test {
namespace {

using device::ForceCommandSample;
using device::SafetyState;

// Rounding of a norm of three doubles of a few newtons: 1e-9 N is far below
// anything a device resolves and far above double rounding (1e-15 N).
constexpr double kForceToleranceN = 1e-9;

class SafetyTest : public testing::Test {
 protected:
  SafetyTest() : core_(config(), backend_) {}

  static device::GatewayConfig config() { return device::GatewayConfig{}; }

  // A command answering the newest published pose (seq = ticks so far).
  ForceCommandSample command(const Vec3& force_n) const {
    ForceCommandSample c;
    c.answered_pose_seq = core_.ticks();
    c.answered_position_m = backend_.reading.position_m;
    c.force_n = force_n;
    return c;
  }

  const device::DevicePoseSample& tick(const ForceCommandSample* c) {
    const Vec3 previous = last_force_n_;
    const auto& pose = core_.tick(tick_time(core_.ticks()), c);
    // The invariants of every tick, whatever arrived.
    EXPECT_TRUE(pose.rendered_force_n.allFinite());
    EXPECT_LE(pose.rendered_force_n.norm(), core_.config().model.peak_force_n + kForceToleranceN);
    EXPECT_LE((pose.rendered_force_n - previous).norm(), max_step_n() + kForceToleranceN);
    last_force_n_ = pose.rendered_force_n;
    return pose;
  }

  // Engages with small commands (the no-kick rule) so later ticks render.
  void engage() {
    const ForceCommandSample small = command(Vec3(0.0, 0.1, 0.0));
    for (std::uint32_t i = 0; i <= core_.config().safety.engage_cycles; ++i) {
      ForceCommandSample c = small;
      c.answered_pose_seq = core_.ticks();
      tick(core_.ticks() == 0 ? nullptr : &c);
    }
    ASSERT_EQ(core_.tick(tick_time(core_.ticks()), nullptr).safety_state,
              SafetyState::kForceEnabled);
  }

  double max_step_n() const {
    return core_.config().safety.max_force_rate_nps *
           std::chrono::duration<double>(core_.config().period).count();
  }

  ScriptedBackend backend_;
  device::ServoCore core_;
  Vec3 last_force_n_ = Vec3::Zero();
};

TEST_F(SafetyTest, HugeForcesAndWildStiffnessNeverExceedPeakOrRate) {
  engage();
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-3, 300);
  double peak_seen_n = 0.0;
  for (int i = 0; i < 5000; ++i) {
    // The stylus wanders within 5 mm so the K correction is exercised.
    backend_.reading.position_m = Vec3(unit(rng), unit(rng), unit(rng)) * 5e-3;
    backend_.reading.linear_velocity_mps = Vec3(unit(rng), unit(rng), unit(rng)) * 0.2;
    const double scale = std::pow(10.0, exponent(rng));
    ForceCommandSample c = command(Vec3(unit(rng), unit(rng), unit(rng)) * scale);
    for (int k = 0; k < 9; ++k)
      c.stiffness_npm(k / 3, k % 3) = unit(rng) * std::pow(10.0, exponent(rng) % 12);
    const auto& pose = tick(&c);
    peak_seen_n = std::max(peak_seen_n, pose.rendered_force_n.norm());
  }
  const auto& counters = core_.safety_counters();
  EXPECT_GT(counters.saturated_ticks, 4000U);
  EXPECT_GT(counters.rate_limited_ticks, 1000U);
  EXPECT_EQ(counters.non_finite_outputs, 0U);
  EXPECT_GT(peak_seen_n,
            0.9 * core_.config().model.peak_force_n);  // the limit is reached, not avoided
  std::printf(
      "hostile forces: peak rendered %.4f N (limit %.2f N), saturated %llu, rate-limited %llu "
      "ticks\n",
      peak_seen_n, core_.config().model.peak_force_n,
      static_cast<unsigned long long>(counters.saturated_ticks),
      static_cast<unsigned long long>(counters.rate_limited_ticks));
}

TEST_F(SafetyTest, SaturationScalesTheVectorKeepingItsDirection) {
  engage();
  const Vec3 huge(3e6, -4e6, 0.0);
  for (int i = 0; i < 20; ++i) {
    const ForceCommandSample c = command(huge);
    tick(&c);
  }
  const Vec3 rendered = last_force_n_;
  EXPECT_NEAR(rendered.norm(), core_.config().model.peak_force_n, 1e-9);
  EXPECT_NEAR(rendered.normalized().dot(huge.normalized()), 1.0, 1e-12);
}

TEST_F(SafetyTest, ForceStepsAreRateLimited) {
  engage();
  int steps_cut = 0;
  for (int i = 0; i < 200; ++i) {
    const double sign = (i / 3) % 2 == 0 ? 1.0 : -1.0;  // +-peak every 3 ms
    const ForceCommandSample c = command(Vec3(sign * 7.9, 0.0, 0.0));
    const Vec3 before = last_force_n_;
    tick(&c);
    if ((last_force_n_ - before).norm() >= max_step_n() - kForceToleranceN) ++steps_cut;
  }
  EXPECT_GT(steps_cut, 150);
  EXPECT_GE(core_.safety_counters().rate_limited_ticks, 150U);
}

TEST_F(SafetyTest, NonFiniteCommandsAreRejectedAndCounted) {
  engage();
  const double bad_values[] = {std::numeric_limits<double>::quiet_NaN(),
                               std::numeric_limits<double>::infinity(),
                               -std::numeric_limits<double>::infinity()};
  std::uint64_t injected = 0;
  for (int round = 0; round < 30; ++round) {
    for (double bad : bad_values) {
      // One bad field at a time, in each of the four fields the gateway reads.
      for (int field = 0; field < 4; ++field) {
        ForceCommandSample c = command(Vec3(0.0, 1.0, 0.0));
        if (field == 0) c.force_n.y() = bad;
        if (field == 1) c.answered_position_m.x() = bad;
        if (field == 2) c.stiffness_npm(2, 1) = bad;
        if (field == 3) c.torque_nm.z() = bad;
        tick(&c);
        ++injected;
        // A good command between bad ones keeps the silence rule quiet.
        const ForceCommandSample good = command(Vec3(0.0, 1.0, 0.0));
        tick(&good);
      }
    }
  }
  EXPECT_EQ(core_.safety_counters().rejected_non_finite, injected);
  EXPECT_EQ(core_.safety_counters().non_finite_outputs, 0U);
  EXPECT_NEAR(last_force_n_.y(), 1.0, 1e-12);  // the good commands still render
}

TEST_F(SafetyTest, SilenceRampsForceToZero) {
  engage();
  for (int i = 0; i < 50; ++i) {
    const ForceCommandSample c = command(Vec3(0.0, 2.0, 0.0));
    tick(&c);
  }
  ASSERT_NEAR(last_force_n_.y(), 2.0, 1e-12);
  const auto& safety = core_.config().safety;
  // Silent: the force holds for silence_periods ticks...
  for (std::uint32_t i = 0; i < safety.silence_periods; ++i) {
    EXPECT_EQ(tick(nullptr).safety_state, SafetyState::kForceEnabled);
  }
  // ...then ramps down monotonically and reaches zero within the ramp time.
  const auto ramp_ticks = static_cast<int>(std::ceil(safety.ramp_down_time.count() / 1e-3));
  double previous = last_force_n_.norm();
  int ticks_to_zero = 0;
  for (int i = 0; i < ramp_ticks + 5 && last_force_n_.norm() > 0.0; ++i) {
    const auto& pose = tick(nullptr);
    EXPECT_LE(pose.rendered_force_n.norm(), previous + kForceToleranceN);
    previous = pose.rendered_force_n.norm();
    ++ticks_to_zero;
  }
  EXPECT_EQ(last_force_n_.norm(), 0.0);
  EXPECT_LE(ticks_to_zero, ramp_ticks + 1);
  EXPECT_EQ(tick(nullptr).safety_state, SafetyState::kForceDisabled);
  EXPECT_EQ(core_.safety_counters().silence_events, 1U);
}

TEST_F(SafetyTest, CommandsBackDuringTheRampResumeWithoutAStep) {
  engage();
  for (int i = 0; i < 50; ++i) {
    const ForceCommandSample c = command(Vec3(0.0, 3.0, 0.0));
    tick(&c);
  }
  const auto& safety = core_.config().safety;
  for (std::uint32_t i = 0; i < safety.silence_periods + 30; ++i) tick(nullptr);
  ASSERT_EQ(tick(nullptr).safety_state, SafetyState::kRampingDown);
  const double ramped_n = last_force_n_.norm();
  ASSERT_LT(ramped_n, 3.0);
  ASSERT_GT(ramped_n, 0.0);
  // A different, larger force arrives: resumed, but only at the rate limit.
  const ForceCommandSample c = command(Vec3(0.0, 7.0, 0.0));
  const auto& pose = tick(&c);
  EXPECT_EQ(pose.safety_state, SafetyState::kForceEnabled);
  EXPECT_NEAR(pose.rendered_force_n.y(), ramped_n + max_step_n(), 1e-9);
  EXPECT_EQ(core_.safety_counters().resumed_events, 1U);
}

// The servo loop itself stalled for a second (SIGSTOP) while the hand moved
// 4 mm against the command's local stiffness, and a command sent meanwhile
// arrives with its first tick back: the missed periods count as silence and
// the command as stale, so that tick ramps down from the commanded force
// instead of rendering F_k - K_k dx four millimetres from x_k (which steps
// the force by the rate limit).
TEST_F(SafetyTest, AStalledServoLoopRampsDownWithoutAStep) {
  engage();
  ForceCommandSample c = command(Vec3(0.0, 2.0, 0.0));
  c.stiffness_npm(1, 1) = 1000.0;
  for (int i = 0; i < 50; ++i) {
    c.answered_pose_seq = core_.ticks();
    tick(&c);
  }
  ASSERT_NEAR(last_force_n_.y(), 2.0, 1e-9);
  backend_.reading.position_m.y() += 4e-3;  // into the command's direction: K dx = 4 N
  // A command sent while the loop was stopped answers a pose from before.
  c.answered_pose_seq = core_.ticks();
  c.force_n = Vec3(0.0, 2.5, 0.0);
  const std::uint64_t stale_before = core_.safety_counters().rejected_stale;
  const auto& pose = core_.tick(tick_time(core_.ticks() + 1000), &c);
  EXPECT_EQ(core_.safety_counters().rejected_stale, stale_before + 1);
  EXPECT_EQ(pose.safety_state, SafetyState::kRampingDown);
  EXPECT_LE((pose.rendered_force_n - last_force_n_).norm(), core_.config().safety.resume_step_n)
      << "rendered " << pose.rendered_force_n.transpose();
  EXPECT_GT(pose.rendered_force_n.norm(), 0.0);
}

// A command marked as a transition (the haptic service ramping or slewing)
// moves the output at most resume_step_n a tick, however far it jumps (two
// commands landing in one tick, the older skipped); an ordinary one at the
// rate limit.
TEST_F(SafetyTest, TransitionCommandsMoveAtTheResumeStep) {
  engage();
  const double step_n = core_.config().safety.resume_step_n;
  ForceCommandSample c = command(Vec3(0.0, 1.0, 0.0));
  c.transition = true;
  double previous = last_force_n_.y();
  for (int i = 0; i < 5; ++i) {
    c.answered_pose_seq = core_.ticks();
    tick(&c);
    EXPECT_NEAR(last_force_n_.y() - previous, step_n, 1e-12);
    previous = last_force_n_.y();
  }
  ForceCommandSample ordinary = command(Vec3(0.0, 1.0, 0.0));
  tick(&ordinary);
  EXPECT_NEAR(last_force_n_.y(), 1.0, 1e-12);
}

TEST_F(SafetyTest, EngagingCatchesUpAtTheResumeStep) {
  // Commands of 0.25 N (small enough to engage): on the tick the device
  // engages, the output climbs at resume_step_n a tick until it meets them.
  const double step_n = core_.config().safety.resume_step_n;
  std::vector<double> enabled;
  for (int i = 0; i < 100; ++i) {
    const ForceCommandSample c = command(Vec3(0.0, 0.25, 0.0));
    const auto& pose = tick(core_.ticks() == 0 ? nullptr : &c);
    if (pose.safety_state == SafetyState::kForceEnabled)
      enabled.push_back(pose.rendered_force_n.y());
  }
  ASSERT_GE(enabled.size(), 3U);
  EXPECT_NEAR(enabled[0], step_n, 1e-12);
  EXPECT_NEAR(enabled[1], 2 * step_n, 1e-12);
  EXPECT_NEAR(enabled[2], 0.25, 1e-12);
  EXPECT_EQ(core_.safety_counters().catch_up_ticks, 2U);
}

TEST_F(SafetyTest, NoKickOnConnect) {
  // The haptic service connects while the stylus is deep in tissue: 5 N.
  for (int i = 0; i < 300; ++i) {
    const ForceCommandSample c = command(Vec3(0.0, 5.0, 0.0));
    const auto& pose = tick(core_.ticks() == 0 ? nullptr : &c);
    EXPECT_EQ(pose.rendered_force_n.norm(), 0.0);
    if (i > 0) {
      EXPECT_EQ(pose.safety_state, SafetyState::kEngaging);
    }
  }
  // The trainee backs off: small commands for engage_cycles ticks engage,
  // one large command in between restarts the count.
  const auto cycles = core_.config().safety.engage_cycles;
  for (std::uint32_t i = 0; i < cycles - 1; ++i) {
    const ForceCommandSample c = command(Vec3(0.0, 0.1, 0.0));
    EXPECT_EQ(tick(&c).safety_state, SafetyState::kEngaging);
  }
  const ForceCommandSample large = command(Vec3(0.0, 1.0, 0.0));
  EXPECT_EQ(tick(&large).safety_state, SafetyState::kEngaging);
  for (std::uint32_t i = 0; i < cycles; ++i) {
    const ForceCommandSample c = command(Vec3(0.0, 0.1, 0.0));
    const auto& pose = tick(&c);
    EXPECT_EQ(pose.safety_state,
              i + 1 < cycles ? SafetyState::kEngaging : SafetyState::kForceEnabled);
  }
  EXPECT_EQ(core_.safety_counters().engage_events, 1U);
  // Once engaged, a step to 5 N is a ramp, not a kick.
  const ForceCommandSample step = command(Vec3(0.0, 5.0, 0.0));
  tick(&step);
  EXPECT_LE(last_force_n_.y(), 0.1 + max_step_n() + kForceToleranceN);
}

TEST_F(SafetyTest, StaleOutOfOrderAndFutureAnswersAreIgnored) {
  engage();
  for (int i = 0; i < 100; ++i) {
    const ForceCommandSample c = command(Vec3(0.0, 1.0, 0.0));
    tick(&c);
  }
  const auto max_age = core_.config().safety.max_answer_age_ticks;
  // Far stale: answers a pose max_age + 1 ticks old, with a force that would show.
  ForceCommandSample stale = command(Vec3(0.0, 3.0, 0.0));
  stale.answered_pose_seq = core_.ticks() - max_age - 1;
  tick(&stale);
  EXPECT_EQ(core_.safety_counters().rejected_stale, 1U);
  // Just within the age limit but older than the command in use: out of order.
  ForceCommandSample older = command(Vec3(0.0, 3.0, 0.0));
  older.answered_pose_seq = core_.ticks() - max_age + 5;
  tick(&older);
  EXPECT_EQ(core_.safety_counters().rejected_out_of_order, 1U);
  // From the future (a pose not yet published) and the invalid seq 0.
  ForceCommandSample future = command(Vec3(0.0, 3.0, 0.0));
  future.answered_pose_seq = core_.ticks() + 1;
  tick(&future);
  future.answered_pose_seq = 0;
  tick(&future);
  EXPECT_EQ(core_.safety_counters().rejected_from_future, 2U);
  EXPECT_NEAR(last_force_n_.y(), 1.0, 1e-12);  // none of them rendered
  // Exactly max_age old is not stale, but older than the command in use:
  // still out of order, still not rendered.
  ForceCommandSample oldest_ok = command(Vec3(0.0, 1.5, 0.0));
  oldest_ok.answered_pose_seq = core_.ticks() - max_age;
  const auto accepted_before = core_.safety_counters().accepted;
  tick(&oldest_ok);
  EXPECT_EQ(core_.safety_counters().accepted, accepted_before);  // older than in use: out of order
}

TEST_F(SafetyTest, BackendFaultZeroesForceAtOnce) {
  engage();
  for (int i = 0; i < 20; ++i) {
    const ForceCommandSample c = command(Vec3(0.0, 2.0, 0.0));
    tick(&c);
  }
  backend_.reading.fault = true;
  const ForceCommandSample c = command(Vec3(0.0, 2.0, 0.0));
  const auto& pose = core_.tick(tick_time(core_.ticks()), &c);
  EXPECT_EQ(pose.rendered_force_n.norm(), 0.0);
  EXPECT_EQ(pose.safety_state, SafetyState::kFault);
  EXPECT_EQ(backend_.applied_n.norm(), 0.0);
}

TEST_F(SafetyTest, TorqueIsLoggedNotRendered) {
  engage();
  ForceCommandSample c = command(Vec3::Zero());
  c.torque_nm = Vec3(0.1, 0.2, 0.3);
  const auto& pose = tick(&c);
  EXPECT_EQ(pose.logged_torque_nm, Vec3(0.1, 0.2, 0.3));
  EXPECT_EQ(pose.rendered_force_n.norm(), 0.0);
}

TEST(Latency, MotionToForceFromEchoedSeq) {
  ScriptedBackend backend;
  device::ServoCore core(device::GatewayConfig{}, backend);
  // Each command answers the pose published 3 ticks earlier; 1000 commands.
  for (std::uint64_t t = 0; t < 1003; ++t) {
    ForceCommandSample c;
    c.answered_pose_seq = t >= 3 ? t - 2 : 0;  // pose of tick t-3 has seq t-2
    core.tick(tick_time(t), t >= 3 ? &c : nullptr);
  }
  const auto& histogram = core.latency();
  EXPECT_EQ(histogram.count(), 1000U);
  EXPECT_EQ(histogram.percentile(0.5), std::chrono::milliseconds(3));
  EXPECT_EQ(histogram.percentile(0.99), std::chrono::milliseconds(3));
  EXPECT_EQ(histogram.max(), std::chrono::milliseconds(3));
}

TEST(Latency, HistogramPercentilesAndOverflow) {
  device::LatencyHistogram histogram(std::chrono::microseconds(10));
  for (int i = 1; i <= 100; ++i) histogram.record(std::chrono::microseconds(i * 10 - 5));
  EXPECT_EQ(histogram.percentile(0.5), std::chrono::microseconds(500));
  EXPECT_EQ(histogram.percentile(0.99), std::chrono::microseconds(990));
  histogram.record(std::chrono::seconds(1));
  EXPECT_EQ(histogram.overflow(), 1U);
  EXPECT_EQ(histogram.percentile(1.0), std::chrono::seconds(1));
}

}  // namespace
}  // namespace fahr::test
