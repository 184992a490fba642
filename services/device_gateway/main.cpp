// fahr_device_gateway: the 1 kHz servo loop of the haptic domain. Thin: it
// builds the back-end and fahr::device::ServoCore from the flags, then runs
// the core in real time (sleep_until, opt-in spin and SCHED_FIFO) or in
// lockstep (one tick per granted base step), publishing DevicePose every tick
// and ServiceStatus a few times a second.
#include <sys/mman.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "fahr/common/clock.h"
#include "fahr/common/config_error.h"
#include "fahr/common/lockstep.h"
#include "fahr/common/participant.h"
#include "fahr/common/publisher.h"
#include "fahr/common/realtime.h"
#include "fahr/common/stop_signal.h"
#include "fahr/common/subscriber.h"
#include "fahr/device/recording.h"
#include "fahr/device/remote_input_backend.h"
#include "fahr/device/replay_backend.h"
#include "fahr/device/servo_core.h"
#include "fahr/device/simulated_backend.h"
#ifdef FAHR_HAVE_OPENHAPTICS
#include "fahr/device/openhaptics_backend.h"
#endif
#include "fahr/common/service_reporter.h"
#include "fahr/gateway_service/gateway_options.h"
#include "fahr/gateway_service/msg_conversion.h"
#include "fahr/gateway_service/status_reporter.h"

namespace fahr::gateway_service {
namespace {

using namespace std::chrono_literals;

// The remote-input topic (the browser's mouse device publishes DevicePose there).
constexpr std::string_view kRemoteInputTopic = "fahr/RemoteInput";
// Poses kept for --record-file are preallocated: at most this many seconds.
constexpr double kMaxRecordedSeconds = 3600.0;

struct Setup {
  device::GatewayConfig config;
  std::unique_ptr<device::Backend> backend;
  device::RemoteInputBackend* remote = nullptr;  // non-null for --backend remote
  double duration_s = 0.0;                       // 0: until SIGINT
};

// Builds the back-end; nullopt (after a message) if it cannot be.
std::optional<Setup> make_setup(const GatewayOptions& o) {
  Setup s;
  if (!device::model_by_name(o.model, s.config.model)) {
    std::fprintf(stderr, "fahr_device_gateway: --model: unknown device '%s' (touch_x, touch)\n",
                 o.model.c_str());
    return std::nullopt;
  }
  s.duration_s = o.duration_s;
  if (o.backend == "simulated") {
    device::Script script = device::Script::kIntubation;
    device::script_by_name(o.script, script);
    const device::HandImpedance hand;
    auto trajectory =
        script == device::Script::kIntubation
            ? device::intubation_script()
            : device::overshoot_script(s.config.model.peak_force_n, hand.stiffness_npm);
    if (s.duration_s == 0.0) s.duration_s = trajectory.duration().count();
    s.backend = std::make_unique<device::SimulatedBackend>(
        std::move(trajectory), hand, s.config.model, s.config.mapping, s.config.period);
  } else if (o.backend == "replay") {
    device::Recording recording;
    if (const std::string error = device::read_recording(o.replay_file, recording);
        !error.empty()) {
      std::fprintf(stderr, "fahr_device_gateway: --replay-file: %s\n", error.c_str());
      return std::nullopt;
    }
    if (s.duration_s == 0.0 && !recording.samples.empty()) {
      s.duration_s = 1e-9 * static_cast<double>(recording.samples.back().device_time_ns -
                                                recording.samples.front().device_time_ns) +
                     1e-3;
    }
    s.backend = std::make_unique<device::ReplayBackend>(std::move(recording));
  } else if (o.backend == "remote") {
    auto remote = std::make_unique<device::RemoteInputBackend>(s.config.model);
    s.remote = remote.get();
    s.backend = std::move(remote);
  } else {
#ifdef FAHR_HAVE_OPENHAPTICS
    std::fprintf(stderr,
                 "fahr_device_gateway: the OpenHaptics servo loop runs in the HD scheduler; "
                 "use --mode realtime (not wired to the HD scheduler in this build yet)\n");
#else
    std::fprintf(
        stderr,
        "fahr_device_gateway: built without OpenHaptics (HD/hd.h and libHD not found by CMake)\n");
#endif
    return std::nullopt;
  }
  return s;
}

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

// What the servo thread keeps between ticks for the status and the recording.
struct LoopState {
  StatusSnapshot snapshot;
  std::vector<device::DevicePoseSample> recorded;
  bool recording = false;
  std::uint64_t seq_mismatches = 0;
};

void fill_snapshot(const device::ServoCore& core, const Setup& setup, LoopState& state) {
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
}

void after_tick(const device::DevicePoseSample& pose, std::uint64_t written_seq, LoopState& state) {
  if (written_seq != pose.seq) ++state.seq_mismatches;
  state.snapshot.safety_state = pose.safety_state;
  if (state.recording && state.recorded.size() < state.recorded.capacity())
    state.recorded.push_back(pose);
}

int run_realtime(const GatewayOptions& o, Setup& setup, common::Participant& participant,
                 GatewayMetrics& metrics, common::TickRecorder& recorder, LoopState& state) {
  device::ServoCore core(setup.config, *setup.backend);
  common::Publisher<msg::DevicePose> pose_pub(participant);
  common::Subscriber<msg::ForceCommand> command_sub(participant);
  std::unique_ptr<common::Subscriber<msg::DevicePose>> remote_sub;
  if (setup.remote != nullptr) {
    remote_sub = std::make_unique<common::Subscriber<msg::DevicePose>>(
        participant, common::QosProfile::for_role(common::TopicRole::kServoStream),
        kRemoteInputTopic);
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
    wait_until(deadline_ns, static_cast<std::int64_t>(o.spin_us) * 1000);
  }
  fill_snapshot(core, setup, state);
  metrics.offer(state.snapshot);
  return 0;
}

int run_lockstep(const GatewayOptions& o, Setup& setup, common::Participant& participant,
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
  fill_snapshot(core, setup, state);
  metrics.offer(state.snapshot);
  std::printf("lockstep: %llu steps, DevicePose hash %016llx\n",
              static_cast<unsigned long long>(core.ticks()),
              static_cast<unsigned long long>(hash.value()));
  return 0;
}

int run(int argc, char** argv) {
  const auto options = parse_options(argc, argv);
  if (!options) return 2;
  auto setup = make_setup(*options);
  if (!setup) return 2;
  common::install_stop_handlers();
  common::Participant participant(common::transport_config_from(
      options->dds, options->domain, options->profile, "device_gateway"));
  common::TickRecorder recorder;
  GatewayMetrics metrics;
  common::ServiceReporter reporter(
      participant,
      {"device_gateway", 1000.0,
       std::chrono::milliseconds(static_cast<long>(1000.0 / options->status_hz))},
      recorder, [&metrics](auto& figures) { metrics.fill(figures); });
  LoopState state;
  if (!options->record_file.empty()) {
    const double seconds = setup->duration_s > 0.0 ? setup->duration_s : kMaxRecordedSeconds;
    state.recorded.reserve(static_cast<std::size_t>(seconds * 1000.0) + 1);
    state.recording = true;
  }
  std::fprintf(stderr, "fahr_device_gateway: %s, backend %s, model %s, %s, %.1f s\n",
               std::string(common::vendor_name(participant.vendor())).c_str(),
               options->backend.c_str(), setup->config.model.name.c_str(), options->mode.c_str(),
               setup->duration_s);
  reporter.set_state(msg::SERVICE_RUNNING);
  const int code = options->mode == "lockstep"
                       ? run_lockstep(*options, *setup, participant, metrics, recorder, state)
                       : run_realtime(*options, *setup, participant, metrics, recorder, state);
  reporter.set_state(msg::SERVICE_STOPPING);
  reporter.report();
  std::printf("device_gateway: %s\n", metrics.summary(reporter.late_periods()).c_str());
  if (state.seq_mismatches > 0) {
    std::fprintf(stderr,
                 "fahr_device_gateway: %llu DevicePose seq mismatches (pose seq != writer seq)\n",
                 static_cast<unsigned long long>(state.seq_mismatches));
  }
  if (state.recording) {
    device::RecordingWriter writer(options->record_file);
    if (!writer.ok()) {
      std::fprintf(stderr, "fahr_device_gateway: --record-file: %s\n", writer.error().c_str());
      return 1;
    }
    for (const auto& pose : state.recorded) writer.write(pose);
    std::printf("device_gateway: %zu DevicePose samples written to %s\n", state.recorded.size(),
                options->record_file.c_str());
  }
  return code;
}

}  // namespace
}  // namespace fahr::gateway_service

int main(int argc, char** argv) {
  try {
    return fahr::gateway_service::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_device_gateway: %s\n", e.what());
    return 1;
  }
}
