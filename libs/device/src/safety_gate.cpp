// The safety layer: command screening and the per-tick state machine.
#include "fahr/device/safety_gate.h"

#include <algorithm>
#include <cmath>

namespace fahr::device {

Vec3 saturate(const Vec3& force_n, double limit_n) {
  // stableNorm: a finite vector near DBL_MAX must not square to infinity.
  const double magnitude = force_n.stableNorm();
  if (magnitude <= limit_n) return force_n;
  return force_n * (limit_n / magnitude);
}

SafetyGate::SafetyGate(const SafetyConfig& config, std::chrono::duration<double> period)
    : config_(config),
      max_step_n_(config.max_force_rate_nps * period.count()),
      ramp_step_(std::min(1.0, period.count() / config.ramp_down_time.count())) {}

Verdict SafetyGate::screen(const ForceCommandSample& command, std::uint64_t newest_published_seq,
                           std::uint64_t active_answered_seq) {
  ++counters_.commands_seen;
  const bool finite = command.answered_position_m.allFinite() && command.force_n.allFinite() &&
                      command.stiffness_npm.allFinite() && command.torque_nm.allFinite();
  if (!finite) {
    ++counters_.rejected_non_finite;
    return Verdict::kNonFinite;
  }
  if (command.answered_pose_seq == 0 || command.answered_pose_seq > newest_published_seq) {
    ++counters_.rejected_from_future;
    return Verdict::kFromFuture;
  }
  if (newest_published_seq - command.answered_pose_seq > config_.max_answer_age_ticks) {
    ++counters_.rejected_stale;
    return Verdict::kStale;
  }
  if (command.answered_pose_seq < active_answered_seq) {
    ++counters_.rejected_out_of_order;
    return Verdict::kOutOfOrder;
  }
  ++counters_.accepted;
  return Verdict::kAccepted;
}

Vec3 SafetyGate::next_target(const Vec3& candidate_n, const Vec3& commanded_n, bool accepted_now) {
  const bool silent = ticks_since_command_ > config_.silence_periods;
  switch (state_) {
    case SafetyState::kFault:
    case SafetyState::kForceDisabled:
      if (!accepted_now) return Vec3::Zero();
      state_ = SafetyState::kEngaging;
      small_ticks_ = 0;
      [[fallthrough]];
    case SafetyState::kEngaging:
      if (silent) {
        state_ = SafetyState::kForceDisabled;
        return Vec3::Zero();
      }
      small_ticks_ = commanded_n.norm() < config_.engage_threshold_n ? small_ticks_ + 1 : 0;
      if (small_ticks_ < config_.engage_cycles) return Vec3::Zero();
      state_ = SafetyState::kForceEnabled;
      ++counters_.engage_events;
      catching_up_ = true;
      return candidate_n;
    case SafetyState::kForceEnabled:
      if (!silent) return candidate_n;
      state_ = SafetyState::kRampingDown;
      ++counters_.silence_events;
      ramp_factor_ = 1.0;
      [[fallthrough]];
    case SafetyState::kRampingDown:
      if (accepted_now) {
        // Commands are back before the force reached zero: a continuation,
        // not a connect. The rate limit turns any difference into a ramp.
        state_ = SafetyState::kForceEnabled;
        ++counters_.resumed_events;
        return candidate_n;
      }
      ramp_factor_ = std::max(0.0, ramp_factor_ - ramp_step_);
      if (ramp_factor_ <= 0.0) state_ = SafetyState::kForceDisabled;
      return ramp_factor_ * candidate_n;
  }
  return Vec3::Zero();
}

Vec3 SafetyGate::rate_limit(const Vec3& target_n, bool transition) {
  const Vec3 step = target_n - last_output_n_;
  const double size = step.norm();
  if (transition && !catching_up_) {
    const double limit = std::min(max_step_n_, config_.resume_step_n);
    if (size <= limit) return target_n;
    ++counters_.catch_up_ticks;
    return last_output_n_ + step * (limit / size);
  }
  if (catching_up_) {
    // After engaging or resuming: at most resume_step_n a tick until the
    // output meets the commands.
    const double limit = std::min(max_step_n_, config_.resume_step_n);
    if (size <= limit) {
      catching_up_ = false;
      return target_n;
    }
    ++counters_.catch_up_ticks;
    return last_output_n_ + step * (limit / size);
  }
  if (size <= max_step_n_) return target_n;
  ++counters_.rate_limited_ticks;
  return last_output_n_ + step * (max_step_n_ / size);
}

Vec3 SafetyGate::limit(const Vec3& candidate_n, const Vec3& commanded_n, bool accepted_now,
                       bool fault, double renderable_n, bool transition) {
  ticks_since_command_ = accepted_now ? 0 : ticks_since_command_ + 1;
  if (fault) {
    // A faulted device gets no force at all, not even a ramp.
    state_ = SafetyState::kFault;
    ++counters_.fault_ticks;
    last_output_n_.setZero();
    return last_output_n_;
  }
  const Vec3 target = next_target(candidate_n, commanded_n, accepted_now);
  const Vec3 saturated = saturate(target, renderable_n);
  if (saturated.norm() < target.norm()) ++counters_.saturated_ticks;
  // Saturate, rate limit, saturate again: the second pass only bites if the
  // renderable force itself fell faster than the rate limit (limits first).
  Vec3 output = saturate(rate_limit(saturated, transition), renderable_n);
  if (!output.allFinite()) {
    ++counters_.non_finite_outputs;
    output.setZero();
  }
  last_output_n_ = output;
  return output;
}

}  // namespace fahr::device
