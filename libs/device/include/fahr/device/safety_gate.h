// The gateway's safety layer: whatever arrives on ForceCommand, the force
// sent to the device stays within the limits. Two tiers, as STYLE.md asks:
// screen() judges each incoming command (rejects and counts it), limit()
// shapes every tick's force and runs the safety state machine:
//
//   DISABLED --(accepted command)--> ENGAGING --(force small for
//   engage_cycles ticks)--> ENABLED --(no command for silence_periods
//   ticks)--> RAMPING_DOWN --(ramp done)--> DISABLED
//   any --(back-end fault)--> FAULT (zero at once) --(fault clears)--> DISABLED
//   RAMPING_DOWN --(command again)--> ENABLED (a dropout shorter than
//   silence + ramp is a continuation: the force was being rendered and the
//   rate limit smooths any difference; a trainee pressing the tongue keeps
//   the tissue under the blade instead of losing it until they back off).
//   After the ramp ends, the next command goes through ENGAGING again.
//
// In every state the output is saturated by scaling the vector to the
// renderable force and its change per tick is bounded (dF/dt), except that
// a fault zeroes it at once.
#pragma once

#include <algorithm>
#include <chrono>
#include <cstdint>

#include "fahr/device/types.h"

namespace fahr::device {

struct SafetyConfig {
  // Ticks without an accepted command before the force ramps down, >= 1.
  // 20 ms: well past the 1.3-4 ms DDS outliers measured on this kind of
  // machine (notes/dependency-facts.md), short enough that a dead haptic
  // service is not felt as a frozen wall.
  std::uint32_t silence_periods = 20;
  // Time to ramp the force from its value at silence to zero, > 0.
  std::chrono::duration<double> ramp_down_time{0.1};
  // "Small" commanded force for engaging, N, >= 0: below what a hand notices
  // as a kick (about 5% of the Touch X peak).
  double engage_threshold_n = 0.3;
  // Consecutive ticks the commanded force must stay small, >= 1 (50 ms).
  std::uint32_t engage_cycles = 50;
  // A command answering a pose older than this many ticks is ignored, >= 1:
  // its correction K_k (x_now - x_k) would extrapolate over too long a path.
  std::uint64_t max_answer_age_ticks = 50;
  // Largest change of the force vector per second, N/s, > 0. 2000 N/s lets
  // the Touch X peak build in 4 ms (a stiff contact) but turns a step from a
  // corrupt command into a ramp the passivity observer can see.
  double max_force_rate_nps = 2000.0;
  // Largest change of the force per tick, N, > 0, from the tick the device
  // engages (ENGAGING -> ENABLED) until the output has caught up with the
  // commands, and while the command in use is a transition (the haptic
  // service ramping or slewing): a haptic service that (re)connects, loses
  // or regains its tissue is never felt as a step.
  // Commands back during a ramp-down keep max_force_rate_nps (a stiff
  // contact must build fast to stay passive); the haptic service slews
  // from the force the device reports then (services/haptic).
  double resume_step_n = 0.1;
};

// Why a command was or was not taken.
enum class Verdict : std::uint8_t {
  kAccepted,
  kNonFinite,   // NaN or infinity in a field
  kStale,       // answers a pose older than max_answer_age_ticks
  kFromFuture,  // answers a pose not yet published (corrupt or foreign)
  kOutOfOrder,  // answers an older pose than the command in use
};

struct SafetyCounters {
  std::uint64_t commands_seen = 0;
  std::uint64_t accepted = 0;
  std::uint64_t rejected_non_finite = 0;
  std::uint64_t rejected_stale = 0;
  std::uint64_t rejected_from_future = 0;
  std::uint64_t rejected_out_of_order = 0;
  std::uint64_t saturated_ticks = 0;     // ticks the magnitude limit cut the force
  std::uint64_t rate_limited_ticks = 0;  // ticks the dF/dt limit cut the change
  std::uint64_t silence_events = 0;      // ENABLED -> RAMPING_DOWN transitions
  std::uint64_t engage_events = 0;       // ENGAGING -> ENABLED transitions
  std::uint64_t resumed_events = 0;      // RAMPING_DOWN -> ENABLED (commands back in time)
  std::uint64_t catch_up_ticks = 0;      // ticks resume_step_n cut the change (engage, transitions)
  std::uint64_t fault_ticks = 0;
  std::uint64_t non_finite_outputs = 0;  // internal error guard; must stay 0
};

// Scales `force_n` down to magnitude `limit_n` (N, >= 0) if it is larger;
// the direction is kept.
Vec3 saturate(const Vec3& force_n, double limit_n);

class SafetyGate {
 public:
  SafetyGate(const SafetyConfig& config, std::chrono::duration<double> period);

  // Judges a command: `newest_published_seq` is the seq of the newest
  // DevicePose already published; `active_answered_seq` that of the command
  // in use (0 if none).
  Verdict screen(const ForceCommandSample& command, std::uint64_t newest_published_seq,
                 std::uint64_t active_answered_seq);

  // One tick. `candidate_n`: the force the renderer (and passivity
  // controller) asks for; `commanded_n`: the renderer's force alone, judged
  // by the engage rule; `accepted_now`: a command was accepted this tick;
  // `renderable_n`: the device's force limit now. Returns the force to send.
  // `transition`: the command in use ramps or slews (ForceCommandSample::
  // transition): the change is bounded by resume_step_n.
  Vec3 limit(const Vec3& candidate_n, const Vec3& commanded_n, bool accepted_now, bool fault,
             double renderable_n, bool transition = false);

  // `ticks` servo ticks went by without a tick of this gate (the servo loop
  // itself stalled): they count as ticks without a command.
  void count_missed_ticks(std::uint64_t ticks) {
    ticks_since_command_ = static_cast<std::uint32_t>(
        std::min<std::uint64_t>(std::uint64_t{ticks_since_command_} + ticks, UINT32_MAX));
  }
  // A command refused as stale by the caller (one that answers a pose from
  // before a stall of the servo loop).
  void count_stale() { ++counters_.rejected_stale; }
  SafetyState state() const { return state_; }
  const SafetyCounters& counters() const { return counters_; }

 private:
  Vec3 next_target(const Vec3& candidate_n, const Vec3& commanded_n, bool accepted_now);
  Vec3 rate_limit(const Vec3& target_n, bool transition);

  SafetyConfig config_;
  double max_step_n_;  // force change allowed per tick, N
  double ramp_step_;   // ramp factor decrement per tick, (0, 1]
  SafetyState state_ = SafetyState::kForceDisabled;
  std::uint32_t ticks_since_command_ = 0;
  std::uint32_t small_ticks_ = 0;
  double ramp_factor_ = 1.0;
  bool catching_up_ = false;  // engaged or resumed, output not yet at the commands
  Vec3 last_output_n_ = Vec3::Zero();
  SafetyCounters counters_;
};

}  // namespace fahr::device
