// The gateway's servo loops (see servo_loop.h).
#include "fahr/gateway_service/servo_loop.h"

#include <sys/mman.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <string_view>
#include <thread>

#include "fahr/common/clock.h"
#include "fahr/common/lockstep.h"
#include "fahr/common/publisher.h"
#include "fahr/common/realtime.h"
#include "fahr/common/stop_signal.h"
#include "fahr/common/subscriber.h"
#include "fahr/device/recording.h"
#include "fahr/gateway_service/msg_conversion.h"

namespace fahr::gateway_service {
namespace {

using namespace std::chrono_literals;

// The remote-input topic (the browser's mouse device publishes DevicePose there).
constexpr std::string_view kRemoteInputTopic = "fahr/RemoteInput";
// Poses kept for --record-file are preallocated: at most this many seconds.
constexpr double kMaxRecordedSeconds = 3600.0;
// Periods behind schedule after which the real-time loop gives up the
// missed ticks and starts again from now (50 ms).
constexpr std::int64_t kResyncPeriods = 50;

void try_realtime(int priority) {
  if (priority <= 0) return;
  // Opt-in: lock memory (no page faults in the loop) and run SCHED_FIFO.
  // Both need privileges; without them the loop runs as a normal thread.
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    std::fprintf(stderr, "fahr_device_gateway: mlockall failed (%s): continuing unlocked\n",
                 std::strerror(errno));
  }
  const std::string refused = common::request_realtime_priority(priority);
  if (!refused.empty()) {
    std::fprintf(stderr, "fahr_device_gateway: SCHED_FIFO %d: %s; continuing at normal priority\n",
                 priority, refused.c_str());
  } else {
    std::fprintf(stderr, "fahr_device_gateway: running SCHED_FIFO priority %d\n", priority);
  }
}

// Sleeps until `deadline_ns` (monotonic), spinning the last `spin_ns`.
void wait_until(std::int64_t deadline_ns, std::int64_t spin_ns) {
  const std::int64_t sleep_until_ns = deadline_ns - spin_ns;
  const std::int64_t now_ns = common::monotonic_now_ns();
  if (sleep_until_ns > now_ns)
    std::this_thread::sleep_for(std::chrono::nanoseconds(sleep_until_ns - now_ns));
  while (common::monotonic_now_ns() < deadline_ns) {
  }
}

void fill_snapshot(const device::ServoCore& core, const GatewaySetup& setup, LoopState& state) {
  StatusSnapshot& s = state.snapshot;
  s.ticks = core.ticks();
  s.safety = core.safety_counters();
  s.renderable_force_n = core.thermal().renderable_force_n();
  s.peak_force_n = core.peak_rendered_force_n();
  s.heat = core.thermal().heat();
  s.energy_to_hand_j = core.energy_to_hand_j();
  s.passivity_dissipated_j = core.passivity().dissipated_energy_j();
  s.passivity_active_ticks = core.passivity().active_ticks();
  s.remote_rejected = setup.remote != nullptr ? setup.remote->rejected_non_finite() : 0;
  s.motion_to_force = core.latency();
  s.motion_to_force_run = core.run_latency();
}

void after_tick(const device::DevicePoseSample& pose, std::uint64_t written_seq, LoopState& state) {
  if (written_seq != pose.seq) ++state.seq_mismatches;
  state.snapshot.safety_state = pose.safety_state;
  if (state.recording && state.recorded.size() < state.recorded.capacity())
    state.recorded.push_back(pose);
}

}  // namespace

void prepare_recording(const GatewayOptions& o, const GatewaySetup& setup, LoopState& state) {
  if (o.record_file.empty()) return;
  const double seconds = setup.duration_s > 0.0 ? setup.duration_s : kMaxRecordedSeconds;
  state.recorded.reserve(static_cast<std::size_t>(seconds * 1000.0) + 1);
  state.recording = true;
}

bool write_recording(const GatewayOptions& o, const LoopState& state) {
  if (!state.recording) return true;
  device::RecordingWriter writer(o.record_file);
  if (!writer.ok()) {
    std::fprintf(stderr, "fahr_device_gateway: --record-file: %s\n", writer.error().c_str());
    return false;
  }
  for (const auto& pose : state.recorded) writer.write(pose);
  std::printf("device_gateway: %zu DevicePose samples written to %s\n", state.recorded.size(),
              o.record_file.c_str());
  return true;
}

int run_realtime(const GatewayOptions& o, GatewaySetup& setup, common::Participant& participant,
                 GatewayMetrics& metrics, common::TickRecorder& recorder, LoopState& state) {
  device::ServoCore core(setup.config, *setup.backend);
  common::Publisher<msg::DevicePose> pose_pub(participant);
  // One haptic service at a time: another writer's commands are refused
  // while it has sent within 1 s, and a restarted one is followed after that.
  common::Subscriber<msg::ForceCommand> command_sub(
      participant, common::Admission<msg::ForceCommand>{.takeover = std::chrono::seconds(1),
                                                        .valid = {},
                                                        .counts = metrics.command_admission,
                                                        .wanted = {}});
  std::unique_ptr<common::Subscriber<msg::DevicePose>> remote_sub;
  if (setup.remote != nullptr) {
    remote_sub = std::make_unique<common::Subscriber<msg::DevicePose>>(
        participant, common::QosProfile::for_role(common::TopicRole::kServoStream),
        kRemoteInputTopic);
  }
  // A scripted hand (the simulated and replayed devices) waits at its first
  // tick (at most --wait-haptic-s, 5 s) until the haptic side is matched
  // both ways, which it is once the haptic service is ready: poses
  // sent before that reach nobody, and the script's first second would be
  // lost to discovery. A hand that moves by itself (a Touch X, the remote
  // input) does not wait. Without a match the loop runs anyway; the safety
  // gate keeps the force at zero.
  const bool scripted = o.backend == "simulated" || o.backend == "replay";
  const auto match_until = std::chrono::steady_clock::now() +
                           std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                               std::chrono::duration<double>(o.wait_haptic_s));
  while (scripted && !common::stop_requested() && std::chrono::steady_clock::now() < match_until &&
         (pose_pub.matched_readers() == 0 || command_sub.matched_writers() == 0)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (scripted && (pose_pub.matched_readers() == 0 || command_sub.matched_writers() == 0)) {
    std::fprintf(stderr, "fahr_device_gateway: no haptic service matched within %g s; running\n",
                 o.wait_haptic_s);
  }
  try_realtime(o.rt_priority);
  msg::DevicePose pose_msg;
  device::ForceCommandSample command;
  device::DeviceReading remote_reading;
  const std::int64_t period_ns = setup.config.period.count();
  const auto report_every = static_cast<std::uint64_t>(1000.0 / o.status_hz);
  const auto total_ticks = static_cast<std::uint64_t>(setup.duration_s * 1000.0);
  const std::int64_t start_ns = common::monotonic_now_ns();
  std::int64_t deadline_ns = start_ns;
  for (std::uint64_t tick = 0;
       !common::stop_requested() && (total_ticks == 0 || tick < total_ticks); ++tick) {
    // --- the servo tick: no allocation, blocking or logging from here ...
    const std::int64_t tick_start_ns = common::monotonic_now_ns();
    const std::int64_t cpu_start_ns = common::thread_cpu_now_ns();
    const device::ForceCommandSample* incoming = nullptr;
    if (command_sub.fetch_newest()) {
      from_msg(command_sub.newest(), command);
      incoming = &command;
    }
    if (remote_sub && remote_sub->fetch_newest()) {
      reading_from_msg(remote_sub->newest(), remote_reading);
      setup.remote->push(remote_reading);
    }
    const auto& pose = core.tick(std::chrono::nanoseconds(tick_start_ns - start_ns), incoming);
    to_msg(pose, o.device_id, pose_msg);
    pose_msg.header().sim_step(pose.servo_tick);
    pose_msg.header().sim_time_ns(pose.device_time_ns);
    pose_pub.write(pose_msg);
    after_tick(pose, pose_pub.last_seq(), state);
    recorder.push({tick, tick_start_ns, common::monotonic_now_ns() - tick_start_ns,
                   common::thread_cpu_now_ns() - cpu_start_ns});
    // --- ... to here.
    if ((tick + 1) % report_every == 0) {
      fill_snapshot(core, setup, state);
      metrics.offer(state.snapshot);
      core.latency().reset();
    }
    deadline_ns += period_ns;
    // Far behind (the process was stopped, or starved): a servo loop that
    // ran every missed tick back to back would replay a second of device
    // time in a burst; it starts again from now instead, the ticks skipped.
    const std::int64_t behind_ns = common::monotonic_now_ns() - deadline_ns;
    if (behind_ns > kResyncPeriods * period_ns) {
      state.skipped_ticks += static_cast<std::uint64_t>(behind_ns / period_ns);
      ++state.resyncs;
      deadline_ns = common::monotonic_now_ns();
    }
    wait_until(deadline_ns, static_cast<std::int64_t>(o.spin_us) * 1000);
  }
  fill_snapshot(core, setup, state);
  metrics.offer(state.snapshot);
  std::printf("device_gateway: refused ForceCommands: %s; non-finite %llu\n",
              common::admission_summary(command_sub.admission_counts()).c_str(),
              static_cast<unsigned long long>(core.safety_counters().rejected_non_finite));
  if (state.resyncs > 0) {
    std::printf("device_gateway: %llu times behind by more than %lld periods: %llu ticks skipped\n",
                static_cast<unsigned long long>(state.resyncs),
                static_cast<long long>(kResyncPeriods),
                static_cast<unsigned long long>(state.skipped_ticks));
  }
  return 0;
}

int run_lockstep(const GatewayOptions& o, GatewaySetup& setup, common::Participant& participant,
                 GatewayMetrics& metrics, common::TickRecorder& recorder, LoopState& state) {
  device::ServoCore core(setup.config, *setup.backend);
  common::Publisher<msg::DevicePose> pose_pub(participant,
                                              common::lockstep_output_qos<msg::DevicePose>());
  std::unique_ptr<common::StepInput<msg::ForceCommand>> input;
  if (o.force_input_period > 0)
    input = std::make_unique<common::StepInput<msg::ForceCommand>>(participant);
  common::LockstepClient client(participant, "device_gateway");
  client.join();
  common::OutputHash hash;
  msg::DevicePose pose_msg;
  device::ForceCommandSample command;
  std::uint64_t last_command_seq = 0;
  const auto total_ticks = static_cast<std::uint64_t>(setup.duration_s * 1000.0);
  for (std::uint64_t k = 0; !common::stop_requested() && (total_ticks == 0 || k < total_ticks) &&
                            client.wait_for_grant(k, 20s);
       ++k) {
    const std::int64_t tick_start_ns = common::monotonic_now_ns();
    const std::int64_t cpu_start_ns = common::thread_cpu_now_ns();
    const device::ForceCommandSample* incoming = nullptr;
    if (input) {
      if (const auto step = common::producer_step_for(k, o.force_input_period)) {
        const msg::ForceCommand* sample = input->wait(*step, 20s);
        if (sample == nullptr) {
          std::fprintf(stderr, "fahr_device_gateway: lockstep: ForceCommand of step %llu missing\n",
                       static_cast<unsigned long long>(*step));
          return 1;
        }
        // The read rule hands the same sample to several steps; render it once as new.
        if (sample->header().seq() != last_command_seq) {
          last_command_seq = sample->header().seq();
          from_msg(*sample, command);
          incoming = &command;
        }
      }
    }
    const auto& pose = core.tick(
        std::chrono::nanoseconds(setup.config.period * static_cast<std::int64_t>(k)), incoming);
    to_msg(pose, o.device_id, pose_msg);
    pose_msg.header().sim_step(k);
    pose_msg.header().sim_time_ns(pose.device_time_ns);
    pose_pub.write(pose_msg);
    hash.add(pose_msg);
    after_tick(pose, pose_pub.last_seq(), state);
    client.complete_through(k, hash.value());
    recorder.push({k, tick_start_ns, common::monotonic_now_ns() - tick_start_ns,
                   common::thread_cpu_now_ns() - cpu_start_ns});
    if ((k + 1) % 250 == 0) {
      fill_snapshot(core, setup, state);
      metrics.offer(state.snapshot);
    }
  }
  // Past its own last step, stay until the clock stops the run, so the last
  // acknowledgement and DevicePose reach their readers.
  if (total_ticks != 0 && core.ticks() == total_ticks) client.wait_for_stop(20s);
  fill_snapshot(core, setup, state);
  metrics.offer(state.snapshot);
  std::printf("lockstep: %llu steps, DevicePose hash %016llx\n",
              static_cast<unsigned long long>(core.ticks()),
              static_cast<unsigned long long>(hash.value()));
  return 0;
}

}  // namespace fahr::gateway_service
