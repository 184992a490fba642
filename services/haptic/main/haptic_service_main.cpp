// fahr_haptic_service: the haptic/contact service. One tick per DevicePose
// (the gateway's servo loop is the clock): sphere centres from the newest
// DeformationState, the blade's contacts through the AIST, the contact
// response on the FEM's compliance with the force-aware decision, and a
// ForceCommand and a ContactSet in answer. Real time only for now.
//
//   fahr_haptic_service --scene FILE [--dds V] [--domain N] [--dds-profile F]
//                       [--duration-s S]
#include <CLI/CLI.hpp>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "fahr/common/publisher.h"
#include "fahr/common/service_reporter.h"
#include "fahr/common/stop_signal.h"
#include "fahr/common/subscriber.h"
#include "fahr/runtime/scene_transport.h"
#include "fahr/runtime/service_main.h"
#include "fahr/scene/load_scene.h"
#include "haptic_loop.h"
#include "haptic_setup.h"
#include "scene_publication.h"

namespace fahr::haptic_service {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;


// The vendor and domain: flag, else environment, else the scene (as the FEM
// service does, so both join the same domain from the same scene).

// Ticks until the duration has passed or a signal asks to stop. Blocks only
// between ticks, waiting for the next DevicePose.
void run_realtime(common::Participant& participant, HapticLoop& loop, common::TickRecorder& recorder,
                  double duration_s) {
  common::Subscriber<msg::DevicePose> poses(participant);
  common::Subscriber<msg::DeformationState> states(participant);
  common::Publisher<msg::ForceCommand> commands(participant);
  common::Publisher<msg::ContactSet> contact_sets(participant);
  msg::ForceCommand command;
  msg::ContactSet contacts;
  contacts.contacts().reserve(msg::MAX_CONTACTS);
  const auto start = Clock::now();
  const auto duration = std::chrono::duration<double>(duration_s);
  std::uint64_t seen = 0;
  std::uint64_t tick = 0;
  while (!common::stop_requested()) {
    if (duration_s > 0 && Clock::now() - start > duration) break;
    // 50 ms: short enough to notice a stop request, long enough not to spin.
    seen = poses.wait_for_samples(seen, 50ms);
    if (!poses.fetch_newest()) continue;
    const std::int64_t t0 = common::monotonic_now_ns();
    const std::int64_t c0 = common::thread_cpu_now_ns();
    if (states.fetch_newest()) loop.take_state(states.newest());
    loop.tick(poses.newest(), states.has_sample() ? &states.newest() : nullptr, command, contacts);
    commands.write(command);
    contact_sets.write(contacts);
    recorder.push({tick++, t0, common::monotonic_now_ns() - t0, common::thread_cpu_now_ns() - c0});
  }
}

int run(int argc, char** argv) {
  CLI::App app{"fahr haptic/contact service"};
  std::string scene_path, dds, domain, profile;
  double duration_s = -1;
  app.add_option("--scene", scene_path, "scene file")->required();
  app.add_option("--dds", dds, "DDS vendor: fastdds, cyclonedds, inprocess");
  app.add_option("--domain", domain, "DDS domain id 0-230");
  app.add_option("--dds-profile", profile, "vendor XML configuration");
  app.add_option("--duration-s", duration_s, "stop after this long; 0 runs until SIGINT/SIGTERM (default: the scene's run.duration_s)");
  CLI11_PARSE(app, argc, argv);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // log lines reach a launcher's log file as they happen

  const auto scene = scene::load_scene(scene_path);
  if (scene->run.mode == scene::RunMode::kLockstep) {
    std::fprintf(stderr, "fahr_haptic_service: scene '%s' asks for lockstep; this service runs real time only so far\n",
                 scene->name.c_str());
    return 2;
  }
  if (duration_s < 0) duration_s = std::chrono::duration<double>(scene->run.duration).count();
  common::install_stop_handlers();

  const auto setup_start = Clock::now();
  const HapticSetup setup = set_up(*scene);
  HapticLoop loop(setup);
  const double setup_s = std::chrono::duration<double>(Clock::now() - setup_start).count();

  common::Participant participant(runtime::transport_for(*scene, dds, domain, profile, "haptic"));
  common::TickRecorder recorder;
  const auto status_period = std::chrono::duration_cast<std::chrono::milliseconds>(scene->rates.status_period());
  common::ServiceReporter reporter(participant,
                                   {"haptic", scene->rates.haptic_hz, status_period > 0ms ? status_period : 250ms},
                                   recorder, [&](auto& metrics) { loop.append_metrics(metrics); });
  // Transient local: the writer must live as long as the run for late
  // joiners to get the samples.
  common::Publisher<msg::SceneDescription> scene_out(participant);
  auto descriptions = describe_scene(setup);
  for (auto& d : descriptions) scene_out.write(d);

  std::printf("fahr_haptic_service: ready: %s, body '%s' (%zu nodes, %zu spheres), tool '%s', %zu obstacles, "
              "%.0f Hz, set-up %.2f s\n",
              std::string(common::vendor_name(participant.vendor())).c_str(), setup.deformable->name.c_str(),
              setup.mesh.node_count(), setup.layout.size(), setup.tool->scene_body->name.c_str(), setup.obstacles.size(),
              scene->rates.haptic_hz, setup_s);
  reporter.set_state(msg::SERVICE_RUNNING);
  run_realtime(participant, loop, recorder, duration_s);
  reporter.set_state(msg::SERVICE_STOPPING);
  reporter.report();
  const auto& m = loop.metrics();
  std::printf("fahr_haptic_service: %llu ticks, %llu FEM states, lost-track episodes %llu, peak |F| %.3f N, "
              "free centres %s, worst state update %.0f us, worst query+solve %.0f us\n",
              static_cast<unsigned long long>(m.ticks.load()), static_cast<unsigned long long>(m.fem_states.load()),
              static_cast<unsigned long long>(m.lost_track_episodes.load()), m.peak_force_n.load(),
              m.free_centres.load() ? "yes" : "no", m.state_us_peak.load(), m.solve_us_peak.load());
  return 0;
}

}  // namespace
}  // namespace fahr::haptic_service

int main(int argc, char** argv) {
  return fahr::runtime::run_service_main("fahr_haptic_service", fahr::haptic_service::run, argc, argv);
}
