// fahr_haptic_service: the haptic/contact service. One tick per DevicePose
// (the gateway's servo loop is the clock): sphere centres from the newest
// DeformationState, the blade's contacts through the AIST, the contact
// response on the FEM's compliance with the force-aware decision, and a
// ForceCommand and a ContactSet in answer. Real time (a FEM state thread
// digests DeformationStates beside the tick) or lockstep.
//
//   fahr_haptic_service --scene FILE [--dds V] [--domain N] [--dds-profile F]
//                       [--duration-s S] [--mode realtime|lockstep] [--collision aist|triangle]
//                       [--spin] [--rt-priority N]
#include <CLI/CLI.hpp>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <optional>

#include "fahr/common/background_publisher.h"
#include "fahr/common/lockstep.h"
#include "fahr/common/publisher.h"
#include "fahr/common/realtime.h"
#include "fahr/common/service_reporter.h"
#include "fahr/common/stop_signal.h"
#include "fahr/common/subscriber.h"
#include "fahr/haptic_service/haptic_loop.h"
#include "fahr/haptic_service/haptic_setup.h"
#include "fahr/haptic_service/scene_publication.h"
#include "fahr/haptic_service/tissue_feed.h"
#include "fahr/haptic_service/tissue_snapshot.h"
#include "fahr/metrics/duration_histogram.h"
#include "fahr/runtime/cpu_pinning.h"
#include "fahr/runtime/scene_transport.h"
#include "fahr/runtime/service_main.h"
#include "fahr/runtime/service_options.h"
#include "fahr/scene/load_scene.h"

namespace fahr::haptic_service {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

// A period between ticks longer than this is a late answer (the gateway's
// servo loop runs at 1 ms).
constexpr std::int64_t kLongPeriodNs = 1'500'000;

// Ticks until the duration has passed or a signal asks to stop. Blocks only
// between ticks, waiting for the next DevicePose; FEM states are digested
// on the feed's thread.
// How the real-time loop waits for the next DevicePose.
struct WaitPolicy {
  // Busy-poll instead of sleeping on the subscriber: the tick starts within
  // a microsecond of the pose's arrival, at the price of a whole core.
  bool spin = false;
  // SCHED_FIFO priority of the tick thread, 0 = normal scheduling.
  int rt_priority = 0;
};

void run_realtime(common::Participant& participant, TissueFeed& feed, HapticLoop& loop,
                  common::TickRecorder& recorder, double duration_s, const WaitPolicy& wait) {
  common::Subscriber<msg::DevicePose> poses(participant);
  common::Publisher<msg::ForceCommand> commands(participant);
  // The ContactSet's write (tens of microseconds: serialisation and send)
  // leaves the tick for a thread of its own, which looks for a new set
  // every 0.5 ms; the FEM takes the newest set at its own rate (5 ms) anyway.
  // The ForceCommand, which the gateway's servo loop waits on, is written
  // on the tick.
  common::BackgroundPublisher<msg::ContactSet> contact_sets(participant, 500us, [] {
    msg::ContactSet contacts;
    contacts.contacts().reserve(msg::MAX_CONTACTS);
    return contacts;
  });
  msg::ForceCommand command;
  const auto start = Clock::now();
  const auto duration = std::chrono::duration<double>(duration_s);
  // Whole-run figures of the tick (the status windows hold 250 ms each): its
  // thread-CPU time (the work, whatever the scheduler does) and the wall
  // periods between ticks longer than 1.5 ms (late answers).
  metrics::DurationHistogram tick_cpu(std::chrono::microseconds(5));  // 5 us bins span 10 ms
  // Its parts: the loop's work (query, solve, the messages filled) and the
  // two DDS writes, thread CPU; the tissue query and the response, wall.
  metrics::DurationHistogram work_cpu(std::chrono::microseconds(5));
  metrics::DurationHistogram publish_cpu(std::chrono::microseconds(5));
  metrics::DurationHistogram query_wall(std::chrono::microseconds(5));
  metrics::DurationHistogram response_wall(std::chrono::microseconds(5));
  std::uint64_t long_periods = 0;
  std::int64_t previous_start_ns = 0;
  if (wait.rt_priority > 0) {
    // Opt-in; without the privilege the loop runs on as before.
    const std::string refused = common::request_realtime_priority(wait.rt_priority);
    std::printf("fahr_haptic_service: real-time priority %d: %s\n", wait.rt_priority,
                refused.empty() ? "granted" : refused.c_str());
  }
  std::uint64_t seen = 0;
  std::uint64_t tick = 0;
  std::uint64_t polls = 0;
  while (!common::stop_requested()) {
    if (wait.spin) {
      // Check the clock and the stop flag every 4096 polls only.
      if ((++polls & 4095u) == 0 && duration_s > 0 && Clock::now() - start > duration) break;
      if (!poses.fetch_newest()) continue;
    } else {
      if (duration_s > 0 && Clock::now() - start > duration) break;
      // 50 ms: short enough to notice a stop request, long enough not to spin.
      seen = poses.wait_for_samples(seen, 50ms);
      if (!poses.fetch_newest()) continue;
    }
    const std::int64_t t0 = common::monotonic_now_ns();
    const std::int64_t c0 = common::thread_cpu_now_ns();
    loop.tick(poses.newest(), feed.newest(), command, contact_sets.back());
    const std::int64_t c1 = common::thread_cpu_now_ns();
    commands.write(command);
    contact_sets.publish();
    const std::int64_t c2 = common::thread_cpu_now_ns();
    const std::int64_t cpu_ns = c2 - c0;
    work_cpu.record(std::chrono::nanoseconds(c1 - c0));
    publish_cpu.record(std::chrono::nanoseconds(c2 - c1));
    const TickPhases& phases = loop.last_phases();
    query_wall.record(std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::chrono::duration<double, std::micro>(phases.tissue_query_us)));
    response_wall.record(std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::chrono::duration<double, std::micro>(phases.response_us)));
    recorder.push({tick++, t0, common::monotonic_now_ns() - t0, cpu_ns});
    tick_cpu.record(std::chrono::nanoseconds(cpu_ns));
    if (previous_start_ns != 0 && t0 - previous_start_ns > kLongPeriodNs) ++long_periods;
    previous_start_ns = t0;
  }
  std::printf(
      "fahr_haptic_service: ContactSets handed over %llu, written %llu, refused %llu (the rest "
      "superseded "
      "before their write)\n",
      static_cast<unsigned long long>(contact_sets.handed()),
      static_cast<unsigned long long>(contact_sets.written()),
      static_cast<unsigned long long>(contact_sets.refused()));
  const auto& m = feed.metrics();
  std::printf(
      "fahr_haptic_service: %llu FEM states digested (%llu refused), worst digest %.0f us\n",
      static_cast<unsigned long long>(m.fem_states.load()),
      static_cast<unsigned long long>(m.bad_states.load()), m.digest_us_peak.load());
  const auto us = [](std::chrono::nanoseconds d) { return static_cast<double>(d.count()) / 1e3; };
  std::printf(
      "fahr_haptic_service: tick CPU us median %.0f p99 %.0f p99.9 %.0f max %.0f over %llu ticks; "
      "periods > 1.5 ms: %llu\n",
      us(tick_cpu.percentile(0.5)), us(tick_cpu.percentile(0.99)), us(tick_cpu.percentile(0.999)),
      us(tick_cpu.max()), static_cast<unsigned long long>(tick_cpu.count()),
      static_cast<unsigned long long>(long_periods));
  const auto print_part = [&](const char* name, const metrics::DurationHistogram& h) {
    std::printf(
        "fahr_haptic_service: tick part %-22s us median %.0f p99 %.0f p99.9 %.0f max %.0f\n", name,
        us(h.percentile(0.5)), us(h.percentile(0.99)), us(h.percentile(0.999)), us(h.max()));
  };
  print_part("work (thread CPU)", work_cpu);
  print_part("publishing (thread CPU)", publish_cpu);
  print_part("tissue query (wall)", query_wall);
  print_part("response (wall)", response_wall);
}

// One tick per granted base step (the haptic rate is the base rate). At
// step k the pose is the gateway's of step k-1 and the tissue the FEM's
// newest step before k (common/lockstep.h); step 0 has no pose yet and
// answers with no force, so the gateway's step 1 has a command to read.
int run_lockstep(common::Participant& participant, const HapticSetup& setup, HapticLoop& loop,
                 common::TickRecorder& recorder) {
  const scene::Scene& scene = *setup.scene;
  const auto base = scene.run.base_period;
  const auto haptic_steps = static_cast<std::uint64_t>(scene.rates.haptic_period() / base);
  const auto fem_steps = static_cast<std::uint64_t>(scene.rates.fem_period() / base);
  if (haptic_steps != 1) {
    std::fprintf(
        stderr,
        "fahr_haptic_service: lockstep needs the haptic rate to be the base rate (%.0f Hz)\n",
        1e9 / static_cast<double>(base.count()));
    return 2;
  }
  common::StepInput<msg::DevicePose> poses(participant);
  common::StepInput<msg::DeformationState> states(participant);
  common::Publisher<msg::ForceCommand> commands(participant,
                                                common::lockstep_output_qos<msg::ForceCommand>());
  common::Publisher<msg::ContactSet> contact_sets(participant,
                                                  common::lockstep_output_qos<msg::ContactSet>());
  common::LockstepClient client(participant, "haptic");
  client.join();
  TissueDigest digest(setup);
  TissueSnapshot tissue = digest.make_snapshot();
  msg::ForceCommand command;
  msg::ContactSet contacts;
  contacts.contacts().reserve(msg::MAX_CONTACTS);
  contacts.body_id(setup.deformable->id);
  contacts.layout_fingerprint(loop.layout_fingerprint());  // step 0 answers with no tick
  common::OutputHash hash;
  std::optional<std::uint64_t> digested_fem_step;
  for (std::uint64_t k = 0; !common::stop_requested() && client.wait_for_grant(k, 60s); ++k) {
    const std::int64_t t0 = common::monotonic_now_ns();
    const std::int64_t c0 = common::thread_cpu_now_ns();
    if (const auto f = common::producer_step_for(k, fem_steps); f && f != digested_fem_step) {
      const msg::DeformationState* state = states.wait(*f, 60s);
      if (state == nullptr) {
        std::fprintf(stderr, "fahr_haptic_service: DeformationState of FEM step %llu never came\n",
                     static_cast<unsigned long long>(*f));
        return 1;
      }
      if (!digest.digest(*state, tissue)) {
        std::fprintf(
            stderr,
            "fahr_haptic_service: DeformationState of FEM step %llu does not fit the mesh\n",
            static_cast<unsigned long long>(*f));
        return 1;
      }
      digested_fem_step = f;
    }
    if (const auto p = common::producer_step_for(k, 1)) {
      const msg::DevicePose* pose = poses.wait(*p, 60s);
      if (pose == nullptr) {
        std::fprintf(stderr, "fahr_haptic_service: DevicePose of step %llu never came\n",
                     static_cast<unsigned long long>(*p));
        return 1;
      }
      loop.tick(*pose, tissue, command, contacts);
    }
    command.header().sim_step(k);
    command.header().sim_time_ns(static_cast<std::int64_t>(k) * base.count());
    contacts.header().sim_step(k);
    contacts.header().sim_time_ns(static_cast<std::int64_t>(k) * base.count());
    commands.write(command);
    contact_sets.write(contacts);
    hash.add(command);
    hash.add(contacts);
    recorder.push({k, t0, common::monotonic_now_ns() - t0, common::thread_cpu_now_ns() - c0});
    client.complete_through(k, hash.value());
  }
  std::printf("fahr_haptic_service: lockstep output hash %016llx\n",
              static_cast<unsigned long long>(hash.value()));
  return 0;
}

int run(int argc, char** argv) {
  CLI::App app{"fahr haptic/contact service"};
  runtime::ServiceOptions options;
  runtime::add_service_options(app, options);
  WaitPolicy wait;
  app.add_flag("--spin", wait.spin,
               "real time: busy-poll for DevicePoses (a core of its own) instead of sleeping");
  app.add_option("--rt-priority", wait.rt_priority,
                 "real time: SCHED_FIFO priority 1-99 for the tick thread (needs CAP_SYS_NICE; "
                 "refused gracefully)")
      ->check(CLI::Range(0, 99));
  std::string collision = "aist";
  app.add_option("--collision", collision,
                 "tool-tissue collision: aist (the paper's spheres) or triangle (the baseline it "
                 "is measured against)")
      ->check(CLI::IsMember({"aist", "triangle"}));
  CLI11_PARSE(app, argc, argv);
  runtime::pin_to_cpus(options.cpus);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // log lines reach a launcher's log file as they happen

  const auto scene = scene::load_scene(options.scene_path);
  const bool lockstep = options.lockstep(*scene);
  const double duration_s = options.duration_or_scene_s(*scene);
  common::install_stop_handlers();

  const auto setup_start = Clock::now();
  const HapticSetup setup =
      set_up(*scene, collision == "triangle" ? CollisionMethod::kTriangle : CollisionMethod::kAist);
  HapticLoop loop(setup);
  const double setup_s = std::chrono::duration<double>(Clock::now() - setup_start).count();

  common::Participant participant(
      runtime::transport_for(*scene, options.dds, options.domain, options.profile, "haptic"));
  common::TickRecorder recorder;
  // Real time: FEM states are digested on the feed's own thread.
  std::unique_ptr<TissueFeed> feed;
  if (!lockstep) feed = std::make_unique<TissueFeed>(participant, setup);
  const auto status_period =
      std::chrono::duration_cast<std::chrono::milliseconds>(scene->rates.status_period());
  common::ServiceReporter reporter(
      participant, {"haptic", scene->rates.haptic_hz, status_period > 0ms ? status_period : 250ms},
      recorder, [&](auto& metrics) {
        loop.append_metrics(metrics);
        if (feed) feed->append_metrics(metrics);
      });
  // Transient local: the writer must live as long as the run for late
  // joiners to get the samples.
  common::Publisher<msg::SceneDescription> scene_out(participant);
  auto descriptions = describe_scene(setup);
  for (auto& d : descriptions) scene_out.write(d);

  std::printf(
      "fahr_haptic_service: ready: %s, body '%s' (%zu nodes, %zu spheres, layout 0x%016llx), "
      "tool '%s' (%zu surface samples), "
      "%zu tissue / %zu tool obstacles, %s collision, %.0f Hz, %s, set-up %.2f s\n",
      std::string(common::vendor_name(participant.vendor())).c_str(),
      setup.deformable->name.c_str(), setup.mesh.node_count(), setup.layout.size(),
      static_cast<unsigned long long>(loop.layout_fingerprint()),
      setup.tool->scene_body->name.c_str(), setup.tool_samples.points_m().size(),
      setup.tissue_obstacles.size(), setup.tool_obstacles.size(), collision.c_str(),
      scene->rates.haptic_hz, lockstep ? "lockstep" : "realtime", setup_s);
  reporter.set_state(msg::SERVICE_RUNNING);
  const int status = lockstep
                         ? run_lockstep(participant, setup, loop, recorder)
                         : (run_realtime(participant, *feed, loop, recorder, duration_s, wait), 0);
  reporter.set_state(msg::SERVICE_STOPPING);
  reporter.report();
  const auto& m = loop.metrics();
  std::printf(
      "fahr_haptic_service: %llu ticks on %llu FEM states, lost-track episodes %llu, peak |F| %.3f "
      "N, "
      "worst tick %.0f us\n",
      static_cast<unsigned long long>(m.ticks.load()),
      static_cast<unsigned long long>(m.snapshots.load()),
      static_cast<unsigned long long>(m.lost_track_episodes.load()), m.peak_force_n.load(),
      m.tick_us_peak.load());
  return status;
}

}  // namespace
}  // namespace fahr::haptic_service

int main(int argc, char** argv) {
  return fahr::runtime::run_service_main("fahr_haptic_service", fahr::haptic_service::run, argc,
                                         argv);
}
