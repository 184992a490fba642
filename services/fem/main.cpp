// fahr_fem_service: the FEM deformation service. Steps the scene's
// deformable bodies at the scene's FEM rate, applies each body's newest
// ContactSet (Algorithm 1 projection), publishes a DeformationState per body
// with the contact compliance of the spheres the haptic service is working
// with, and reports its step time and QoS events. Real time or lockstep, as
// the scene says.
//
//   fahr_fem_service --scene FILE [--dds V] [--domain N] [--dds-profile F]
//                    [--duration-s S] [--mode realtime|lockstep] [--cpus LIST]
#include <chrono>
#include <cstdio>
#include <memory>
#include <vector>

#include "fahr/cli/cli.h"
#include "fahr/common/service_reporter.h"
#include "fahr/common/solver_threads.h"
#include "fahr/common/stop_signal.h"
#include "fahr/fem_service/fem_body_setup.h"
#include "fahr/fem_service/fem_loop.h"
#include "fahr/fem_service/service_step.h"
#include "fahr/runtime/cpu_pinning.h"
#include "fahr/runtime/scene_transport.h"
#include "fahr/runtime/service_main.h"
#include "fahr/runtime/service_options.h"
#include "fahr/scene/load_scene.h"

namespace fahr::fem_service {

int run(int argc, char** argv) {
  using namespace std::chrono_literals;
  // Options.
  fahr::cli::App app{"fahr FEM deformation service"};
  runtime::ServiceOptions options;
  runtime::add_service_options(app, options);
  if (const auto exit = app.parse(argc, argv)) return *exit;
  runtime::pin_to_cpus(options.cpus);

  // Set-up: the scene's deformable bodies, the transport, the status reporter.
  const auto scene = scene::load_scene(options.scene_path);
  const std::vector<std::size_t> bodies = choose_bodies(*scene);
  if (bodies.empty()) return 0;
  const bool lockstep = options.lockstep(*scene);
  const double duration_s = options.duration_or_scene_s(*scene);
  common::install_stop_handlers();
  std::vector<std::unique_ptr<FemBodySetup>> setups;
  BodySteps steps;
  for (const std::size_t body : bodies) {
    // In real time a step never waits for a background factorisation; in
    // lockstep it does, so the same inputs give the same bits.
    setups.push_back(std::make_unique<FemBodySetup>(
        set_up_body(*scene, scene->bodies[body],
                    lockstep ? fem::FactorInstall::kWait : fem::FactorInstall::kWhenDone)));
    steps.push_back(std::make_unique<ServiceStep>(*setups.back()));
  }
  common::Participant participant(runtime::transport_for(*scene, options.dds, options.domain,
                                                         options.profile, "fem", options.security));
  common::TickRecorder recorder;
  common::ServiceReporter reporter(
      participant,
      {"fem", scene->rates.fem_hz,
       scene->rates.status_period() > 0ns
           ? std::chrono::duration_cast<std::chrono::milliseconds>(scene->rates.status_period())
           : 250ms},
      recorder, [&](auto& metrics) { append_metrics(steps, metrics); },
      // Refused ContactSets, failed solves, resets: said here, off the step.
      [&](auto& errors) { take_errors(steps, errors); });
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // launchers wait for the start line
  print_start_lines(participant, steps, *scene, lockstep);

  // The loop.
  reporter.set_state(msg::SERVICE_RUNNING);
  const int status = lockstep ? run_lockstep(participant, steps, *scene, recorder)
                              : run_realtime(participant, steps, *scene, recorder, duration_s);

  // Shutdown.
  reporter.set_state(msg::SERVICE_STOPPING);
  reporter.report();
  print_end_lines(steps);
  return status;
}

}  // namespace fahr::fem_service

int main(int argc, char** argv) {
  fahr::common::run_solver_libraries_on_one_thread(argv);
  return fahr::runtime::run_service_main("fahr_fem_service", fahr::fem_service::run, argc, argv);
}
