// fahr_haptic_service: the haptic/contact service. One tick per DevicePose
// (the gateway's servo loop is the clock): sphere centres from the newest
// DeformationState, the blade's contacts through the AIST, the contact
// response on the FEM's compliance with the force-aware decision, and a
// ForceCommand and a ContactSet in answer. Real time (a FEM state thread
// digests DeformationStates beside the tick) or lockstep (service_loop.h).
//
//   fahr_haptic_service --scene FILE [--dds V] [--domain N] [--dds-profile F]
//                       [--duration-s S] [--mode realtime|lockstep] [--collision aist|triangle]
//                       [--spin] [--rt-priority N] [--cpus LIST]
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "fahr/cli/cli.h"
#include "fahr/common/publisher.h"
#include "fahr/common/service_reporter.h"
#include "fahr/common/stop_signal.h"
#include "fahr/haptic_service/haptic_loop.h"
#include "fahr/haptic_service/haptic_setup.h"
#include "fahr/haptic_service/scene_publication.h"
#include "fahr/haptic_service/service_loop.h"
#include "fahr/haptic_service/tissue_feed.h"
#include "fahr/runtime/cpu_pinning.h"
#include "fahr/runtime/scene_transport.h"
#include "fahr/runtime/service_main.h"
#include "fahr/runtime/service_options.h"
#include "fahr/scene/load_scene.h"

namespace fahr::haptic_service {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

int run(int argc, char** argv) {
  // Options.
  fahr::cli::App app{"fahr haptic/contact service"};
  runtime::ServiceOptions options;
  runtime::add_service_options(app, options);
  WaitPolicy wait;
  app.add_flag("--spin", wait.spin,
               "real time: busy-poll for DevicePoses (a core of its own) instead of sleeping");
  app.add_option("--rt-priority", wait.rt_priority,
                 "real time: SCHED_FIFO priority 1-99 for the tick thread (needs CAP_SYS_NICE; "
                 "refused gracefully)")
      ->check(fahr::cli::Range(0, 99));
  std::string collision = "aist";
  app.add_option("--collision", collision,
                 "tool-tissue collision: aist (the paper's spheres) or triangle (the baseline it "
                 "is measured against)")
      ->check(fahr::cli::IsMember({"aist", "triangle"}));
  if (const auto exit = app.parse(argc, argv)) return *exit;
  runtime::pin_to_cpus(options.cpus);
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // log lines reach a launcher's log file as they happen

  // Set-up: the scene's tool and tissue, the transport, the status reporter,
  // the scene's description for late joiners.
  const auto scene = scene::load_scene(options.scene_path);
  const bool lockstep = options.lockstep(*scene);
  const double duration_s = options.duration_or_scene_s(*scene);
  common::install_stop_handlers();
  const auto setup_start = Clock::now();
  const HapticSetup setup =
      set_up(*scene, collision == "triangle" ? CollisionMethod::kTriangle : CollisionMethod::kAist);
  HapticLoop loop(setup);
  const double setup_s = std::chrono::duration<double>(Clock::now() - setup_start).count();
  common::Participant participant(runtime::transport_for(
      *scene, options.dds, options.domain, options.profile, "haptic", options.security));
  common::TickRecorder recorder;
  // Real time: FEM states are digested on the feed's own thread.
  std::unique_ptr<TissueFeed> feed;
  if (!lockstep) feed = std::make_unique<TissueFeed>(participant, setup);
  const auto pose_admission = std::make_shared<common::AdmissionCounts>();
  const auto status_period =
      std::chrono::duration_cast<std::chrono::milliseconds>(scene->rates.status_period());
  common::ServiceReporter reporter(
      participant, {"haptic", scene->rates.haptic_hz, status_period > 0ms ? status_period : 250ms},
      recorder,
      [&](auto& metrics) {
        loop.append_metrics(metrics);
        if (feed) {
          feed->append_metrics(metrics);
          common::append_admission_metrics(*pose_admission, "poses", metrics);
        }
      },
      // The FEM lost and back, a restarted FEM, a silent device: said here.
      [&](auto& errors) { loop.take_errors(errors); });
  // Transient local: the writer must live as long as the run for late
  // joiners to get the samples.
  common::Publisher<msg::SceneDescription> scene_out(participant);
  for (auto& description : describe_scene(setup)) scene_out.write(description);
  print_ready_line(participant, setup, collision, lockstep, setup_s);

  // The loop.
  reporter.set_state(msg::SERVICE_RUNNING);
  const int status =
      lockstep
          ? run_lockstep(participant, setup, loop, recorder)
          : (run_realtime(participant, *feed, loop, recorder, duration_s, wait, pose_admission), 0);

  // Shutdown.
  reporter.set_state(msg::SERVICE_STOPPING);
  reporter.report();
  print_end_line(loop);
  return status;
}

}  // namespace
}  // namespace fahr::haptic_service

int main(int argc, char** argv) {
  return fahr::runtime::run_service_main("fahr_haptic_service", fahr::haptic_service::run, argc,
                                         argv);
}
