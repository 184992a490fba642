// One servo tick (see the header for the order of operations).
#include "fahr/device/servo_core.h"

#include <stdexcept>
#include <string>

namespace fahr::device {

namespace {

void check(const GatewayConfig& config) {
  if (const std::string error = validate(config.model); !error.empty()) {
    throw std::invalid_argument("device model " + config.model.name + ": " + error);
  }
  if (config.period <= std::chrono::nanoseconds(0))
    throw std::invalid_argument("period must be > 0");
  const SafetyConfig& s = config.safety;
  if (s.silence_periods < 1) throw std::invalid_argument("safety.silence_periods must be >= 1");
  if (!(s.ramp_down_time.count() > 0.0))
    throw std::invalid_argument("safety.ramp_down_time must be > 0");
  if (s.engage_cycles < 1) throw std::invalid_argument("safety.engage_cycles must be >= 1");
  if (s.max_answer_age_ticks < 1)
    throw std::invalid_argument("safety.max_answer_age_ticks must be >= 1");
  if (!(s.max_force_rate_nps > 0.0))
    throw std::invalid_argument("safety.max_force_rate_nps must be > 0");
  if (!(s.resume_step_n > 0.0)) throw std::invalid_argument("safety.resume_step_n must be > 0");
  if (!(s.engage_threshold_n >= 0.0))
    throw std::invalid_argument("safety.engage_threshold_n must be >= 0");
  if (!(config.render.max_correction_m > 0.0 && config.render.max_correction_m <= 0.1)) {
    throw std::invalid_argument("render.max_correction_m must be in (0, 0.1] m");
  }
  if (!(config.mapping.motion_scale > 0.0 && config.mapping.motion_scale <= 100.0)) {
    throw std::invalid_argument("mapping.motion_scale must be in (0, 100]");
  }
  if (!(config.passivity.max_damping_nspm >= 0.0 && config.passivity.max_stored_energy_j > 0.0 &&
        config.passivity.max_damping_release_n > 0.0)) {
    throw std::invalid_argument(
        "passivity: max_damping_nspm must be >= 0, max_stored_energy_j > 0, max_damping_release_n "
        "> 0");
  }
}

const GatewayConfig& checked(const GatewayConfig& config) {
  check(config);
  return config;
}

}  // namespace

ServoCore::ServoCore(const GatewayConfig& config, Backend& backend)
    : config_(checked(config)),
      backend_(backend),
      dt_(std::chrono::duration<double>(config.period)),
      thermal_(config.model),
      renderer_(config.render, config.model.max_stiffness_npm),
      passivity_(config.passivity),
      safety_(config.safety, dt_) {
  pose_.max_stiffness_npm = config.model.max_stiffness_npm;
  pose_.renderable_force_n = thermal_.renderable_force_n();
}

const DevicePoseSample& ServoCore::tick(std::chrono::nanoseconds now,
                                        const ForceCommandSample* incoming) {
  // The loop itself stalled (SIGSTOP, a starved machine) for longer than
  // the silence rule allows: the periods it missed were periods without a
  // command, so the silence rule ramps the force down now; a command that
  // arrived meanwhile answers a pose from before the stall and is refused
  // as stale (the pose count did not advance while the clock did); and the
  // command's local stiffness is dropped, since the stylus has moved an
  // unknown way from the pose it answered and F_k - K_k dx there
  // extrapolates past where it holds (a gateway back from a 1 s SIGSTOP
  // stepped the force by 0.39 N on its first tick).
  const auto silence = config_.period * config_.safety.silence_periods;
  const bool stalled = last_now_.count() >= 0 && now - last_now_ > silence;
  if (stalled) {
    safety_.count_missed_ticks(static_cast<std::uint64_t>((now - last_now_) / config_.period) - 1);
    renderer_.drop_stiffness();
  }
  last_now_ = now;
  const DeviceReading reading = backend_.read(now);
  pose_.servo_tick = tick_;
  pose_.seq = tick_ + 1;
  pose_.device_time_ns = now.count();
  config_.mapping.to_world(reading, pose_);
  pose_times_.record(pose_.seq, now);

  bool accepted = false;
  if (incoming != nullptr && stalled) {
    safety_.count_stale();
  } else if (incoming != nullptr) {
    // Only poses of earlier ticks have been published: seq <= tick_.
    const Verdict verdict = safety_.screen(
        *incoming, tick_, renderer_.has_command() ? renderer_.answered_pose_seq() : 0);
    if (verdict == Verdict::kAccepted) {
      accepted = true;
      transition_ = incoming->transition;
      renderer_.set_command(*incoming);
      std::chrono::nanoseconds published{0};
      if (pose_times_.find(incoming->answered_pose_seq, published)) {
        latency_.record(now - published);
        run_latency_.record(now - published);
      }
    }
  }

  const Vec3 commanded = renderer_.render(pose_.position_m);
  const Vec3 velocity = pose_.linear_velocity_mps;
  const Vec3 candidate = passivity_.apply(commanded, velocity, dt_);
  // The limit of this tick is published with it, so rendered <= renderable
  // holds in every DevicePose; the next tick's limit differs by one tick of
  // heating at most.
  const double renderable_n = thermal_.renderable_force_n();
  const Vec3 output =
      safety_.limit(candidate, commanded, accepted, reading.fault, renderable_n, transition_);
  passivity_.account(output, velocity, dt_);
  thermal_.update(output.norm(), dt_);
  backend_.apply(config_.mapping.force_to_device(output));

  energy_to_hand_j_ += output.dot(velocity) * dt_.count();
  peak_rendered_n_ = std::max(peak_rendered_n_, output.norm());
  pose_.rendered_force_n = output;
  pose_.logged_torque_nm = renderer_.torque_nm();
  pose_.renderable_force_n = renderable_n;
  pose_.safety_state = safety_.state();
  ++tick_;
  return pose_;
}

}  // namespace fahr::device
