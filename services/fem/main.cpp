// fahr_fem_service: the FEM deformation service. Steps the scene's
// deformable body at the scene's FEM rate, applies the newest ContactSet
// (Algorithm 1 projection), publishes DeformationState with the contact
// compliance of the spheres the haptic service is working with, and reports
// its step time and QoS events. Real time or lockstep, as the scene says.
//
//   fahr_fem_service --scene FILE [--dds V] [--domain N] [--dds-profile F]
//                    [--duration-s S] [--mode realtime|lockstep]
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <thread>

#include "fahr/common/lockstep.h"
#include "fahr/common/service_reporter.h"
#include "fahr/common/solver_threads.h"
#include "fahr/common/stop_signal.h"
#include "fahr/fem_service/fem_body_setup.h"
#include "fahr/fem_service/service_step.h"
#include "fahr/runtime/cpu_pinning.h"
#include "fahr/runtime/scene_transport.h"
#include "fahr/runtime/service_main.h"
#include "fahr/runtime/service_options.h"
#include "fahr/scene/load_scene.h"
#include "fahr/scene/plan.h"

namespace fahr::fem_service {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

void record(common::TickRecorder& recorder, std::uint64_t tick, std::int64_t start_ns,
            std::int64_t cpu_start_ns) {
  recorder.push({tick, start_ns, common::monotonic_now_ns() - start_ns,
                 common::thread_cpu_now_ns() - cpu_start_ns});
}

int run_realtime(common::Participant& participant, ServiceStep& fem_step, const scene::Scene& scene,
                 common::TickRecorder& recorder, double duration_s) {
  common::QosProfile out_qos = common::QosProfile::for_role(common::TopicRole::kStateStream);
  out_qos.deadline =
      3 * scene.rates.fem_period();  // a late step is expected now and then; three are not
  common::Publisher<msg::DeformationState> out(participant, out_qos);
  common::Subscriber<msg::ContactSet> in(participant);
  const auto period = scene.rates.fem_period();
  const auto start = Clock::now();
  auto next = start;
  for (std::uint64_t tick = 0; !common::stop_requested(); ++tick) {
    next += period;
    std::this_thread::sleep_until(next);
    if (duration_s > 0 && Clock::now() - start > std::chrono::duration<double>(duration_s)) break;
    const std::int64_t t0 = common::monotonic_now_ns();
    const std::int64_t c0 = common::thread_cpu_now_ns();
    if (in.fetch_newest()) fem_step.take(in.newest(), in.newest_info().seq);
    fem_step.step();
    fem_step.state().header().sim_step(fem_step.setup().body->step_index());
    fem_step.state().header().sim_time_ns(
        static_cast<std::int64_t>(fem_step.last_report().time_s * 1e9));
    out.write(fem_step.state());
    record(recorder, tick, t0, c0);
  }
  return 0;
}

int run_lockstep(common::Participant& participant, ServiceStep& fem_step, const scene::Scene& scene,
                 common::TickRecorder& recorder) {
  common::Publisher<msg::DeformationState> out(
      participant, common::lockstep_output_qos<msg::DeformationState>());
  common::StepInput<msg::ContactSet> in(participant);
  common::LockstepClient client(participant, "fem");
  client.join();
  const auto base = scene.run.base_period;
  const auto fem_steps = static_cast<std::uint64_t>(scene.rates.fem_period() / base);
  const auto haptic_steps = static_cast<std::uint64_t>(scene.rates.haptic_period() / base);
  common::OutputHash hash;
  for (std::uint64_t k = 0; !common::stop_requested() && client.wait_for_grant(k, 60s);
       k += fem_steps) {
    const std::int64_t t0 = common::monotonic_now_ns();
    const std::int64_t c0 = common::thread_cpu_now_ns();
    if (auto s = common::producer_step_for(k, haptic_steps)) {
      const msg::ContactSet* set = in.wait(*s, 60s);
      if (set == nullptr) {
        std::fprintf(stderr, "fahr_fem_service: ContactSet of haptic step %llu never came\n",
                     static_cast<unsigned long long>(*s));
        return 1;
      }
      fem_step.take(*set, set->header().seq());
    }
    fem_step.step();
    fem_step.state().header().sim_step(k);
    fem_step.state().header().sim_time_ns(static_cast<std::int64_t>(k) * base.count());
    out.write(fem_step.state());
    hash.add(fem_step.state());
    record(recorder, k, t0, c0);
    client.complete_through(k + fem_steps - 1, hash.value());
  }
  return 0;
}

}  // namespace

int run(int argc, char** argv) {
  CLI::App app{"fahr FEM deformation service"};
  runtime::ServiceOptions options;
  runtime::add_service_options(app, options);
  bool tool_obstacle = false;
  app.add_flag("--tool-obstacle", tool_obstacle,
               "experimental: keep the whole body out of the tool at the ContactSet's tool pose, "
               "not only the "
               "set's spheres (services/fem contact_step.h set_tool_obstacle)");
  CLI11_PARSE(app, argc, argv);
  runtime::pin_to_cpus(options.cpus);

  const auto scene = scene::load_scene(options.scene_path);
  const auto plan = scene::derive_plan(*scene);
  if (!plan.run_fem) {
    std::printf("fahr_fem_service: scene '%s' has no deformable body; nothing to do\n",
                scene->name.c_str());
    return 0;
  }
  if (plan.fem_bodies.size() != 1) {
    std::fprintf(stderr,
                 "fahr_fem_service: scene '%s' has %zu deformable bodies; this service steps one\n",
                 scene->name.c_str(), plan.fem_bodies.size());
    return 2;
  }
  const bool lockstep = options.lockstep(*scene);
  const double duration_s = options.duration_or_scene_s(*scene);

  common::install_stop_handlers();
  FemBodySetup setup = set_up_body(*scene, scene->bodies[plan.fem_bodies.front()]);
  if (tool_obstacle) setup.tool = load_tool_field(*scene);
  ServiceStep fem_step(setup);
  common::Participant participant(
      runtime::transport_for(*scene, options.dds, options.domain, options.profile, "fem"));
  common::TickRecorder recorder;
  common::ServiceReporter reporter(
      participant,
      {"fem", scene->rates.fem_hz,
       scene->rates.status_period() > 0ns
           ? std::chrono::duration_cast<std::chrono::milliseconds>(scene->rates.status_period())
           : 250ms},
      recorder, [&](auto& metrics) { fem_step.metrics(metrics); },
      [&](auto& errors) {
        // Refused ContactSets: said here, off the step, once per change.
        if (std::string error = fem_step.layout_check().take_error(); !error.empty())
          errors.push_back(std::move(error));
      });
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // launchers wait for the start line
  std::printf(
      "fahr_fem_service: %s, body '%s' (%zu nodes, %zu tets, %zu fixed, %zu spheres, layout "
      "0x%016llx), %.0f Hz, %s\n",
      std::string(common::vendor_name(participant.vendor())).c_str(),
      setup.scene_body->name.c_str(), setup.mesh.node_count(), setup.mesh.tet_count(),
      setup.fixed_nodes.size(), setup.links.size(),
      static_cast<unsigned long long>(setup.layout_fingerprint), scene->rates.fem_hz,
      lockstep ? "lockstep" : "realtime");
  reporter.set_state(msg::SERVICE_RUNNING);
  const int status = lockstep ? run_lockstep(participant, fem_step, *scene, recorder)
                              : run_realtime(participant, fem_step, *scene, recorder, duration_s);
  reporter.set_state(msg::SERVICE_STOPPING);
  reporter.report();
  std::printf(
      "fahr_fem_service: %llu steps, stale contact sets %llu, refused (another sphere layout) "
      "%llu, max inverted elements %llu, resets after divergence %llu\n",
      static_cast<unsigned long long>(setup.body->step_index()),
      static_cast<unsigned long long>(fem_step.stale_sets()),
      static_cast<unsigned long long>(fem_step.layout_check().refused()),
      static_cast<unsigned long long>(fem_step.inverted_max()),
      static_cast<unsigned long long>(fem_step.divergence_resets()));
  return status;
}

}  // namespace fahr::fem_service

int main(int argc, char** argv) {
  fahr::common::run_solver_libraries_on_one_thread(argv);
  return fahr::runtime::run_service_main("fahr_fem_service", fahr::fem_service::run, argc, argv);
}
