// The FEM service's run over DDS (see fem_loop.h).
#include "fahr/fem_service/fem_loop.h"

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "fahr/common/lockstep.h"
#include "fahr/common/publisher.h"
#include "fahr/common/stop_signal.h"
#include "fahr/common/subscriber.h"
#include "fahr/scene/plan.h"

namespace fahr::fem_service {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

// A period's CPU is its thread's and what the bodies' background
// factorisations used since the period before (fem
// SolverSettings::background_factor_latency_s).
void record(common::TickRecorder& recorder, BodySteps& steps, std::uint64_t tick,
            std::int64_t start_ns, std::int64_t cpu_start_ns) {
  std::int64_t cpu_ns = common::thread_cpu_now_ns() - cpu_start_ns;
  for (auto& step : steps) cpu_ns += step->take_background_cpu_ns();
  recorder.push({tick, start_ns, common::monotonic_now_ns() - start_ns, cpu_ns});
}

std::vector<std::uint32_t> body_ids(const BodySteps& steps) {
  std::vector<std::uint32_t> ids;
  for (const auto& step : steps) ids.push_back(step->setup().scene_body->id);
  return ids;
}

}  // namespace

std::vector<std::size_t> choose_bodies(const scene::Scene& scene) {
  const auto plan = scene::derive_plan(scene);
  if (!plan.run_fem) {
    std::printf("fahr_fem_service: scene '%s' has no deformable body; nothing to do\n",
                scene.name.c_str());
    return {};
  }
  return plan.fem_bodies;
}

int run_realtime(common::Participant& participant, BodySteps& steps, const scene::Scene& scene,
                 common::TickRecorder& recorder, double duration_s) {
  common::QosProfile out_qos = common::QosProfile::for_role(common::TopicRole::kStateStream);
  out_qos.deadline =
      3 * scene.rates.fem_period();  // a late step is expected now and then; three are not
  // Per body a writer of its states and a reader of its ContactSets. One
  // haptic service at a time: another writer's sets are refused while it has
  // sent within 1 s; a restarted one is followed after that.
  std::vector<std::unique_ptr<common::Publisher<msg::DeformationState>>> out;
  std::vector<std::unique_ptr<common::Subscriber<msg::ContactSet>>> in;
  // A set naming no body of the scene (an intruder's) goes to the first
  // body's reader, to be refused and counted there.
  const std::vector<std::uint32_t> ids = body_ids(steps);
  for (std::size_t b = 0; b < steps.size(); ++b) {
    out.push_back(std::make_unique<common::Publisher<msg::DeformationState>>(participant, out_qos));
    in.push_back(std::make_unique<common::Subscriber<msg::ContactSet>>(
        participant,
        common::Admission<msg::ContactSet>{
            .takeover = std::chrono::seconds(1),
            .valid = {},
            .counts = steps[b]->contact_admission(),
            .wanted = common::body_instance<msg::ContactSet>(ids, b, /*strays=*/true)}));
  }
  const auto period = scene.rates.fem_period();
  const auto start = Clock::now();
  auto next = start;
  std::uint64_t resyncs = 0;
  for (std::uint64_t tick = 0; !common::stop_requested(); ++tick) {
    next += period;
    // Far behind (stopped, starved): start again from now rather than run
    // the missed steps back to back.
    if (Clock::now() - next > 10 * period) {
      next = Clock::now();
      ++resyncs;
    }
    std::this_thread::sleep_until(next);
    if (duration_s > 0 && Clock::now() - start > std::chrono::duration<double>(duration_s)) break;
    const std::int64_t t0 = common::monotonic_now_ns();
    const std::int64_t c0 = common::thread_cpu_now_ns();
    for (std::size_t b = 0; b < steps.size(); ++b) {
      ServiceStep& fem_step = *steps[b];
      if (in[b]->fetch_newest())
        fem_step.take(in[b]->newest(), in[b]->newest_info().seq, common::monotonic_now_ns());
      fem_step.step(common::monotonic_now_ns());
      fem_step.state().header().sim_step(fem_step.setup().body->step_index());
      fem_step.state().header().sim_time_ns(
          static_cast<std::int64_t>(fem_step.last_report().time_s * 1e9));
      out[b]->write(fem_step.state());
    }
    record(recorder, steps, tick, t0, c0);
  }
  if (resyncs > 0) {
    std::printf("fahr_fem_service: %llu times more than 10 steps behind: started again from now\n",
                static_cast<unsigned long long>(resyncs));
  }
  for (std::size_t b = 0; b < steps.size(); ++b) {
    const ServiceStep& fem_step = *steps[b];
    std::printf(
        "fahr_fem_service: %srefused ContactSets: %s, non-finite %llu, unknown sphere %llu, "
        "answering a step not reached %llu\n",
        steps.size() > 1 ? ("body '" + fem_step.setup().scene_body->name + "': ").c_str() : "",
        common::admission_summary(in[b]->admission_counts()).c_str(),
        static_cast<unsigned long long>(fem_step.non_finite_sets()),
        static_cast<unsigned long long>(fem_step.unknown_sphere_sets()),
        static_cast<unsigned long long>(fem_step.ahead_sets()));
  }
  return 0;
}

int run_lockstep(common::Participant& participant, BodySteps& steps, const scene::Scene& scene,
                 common::TickRecorder& recorder) {
  std::vector<std::unique_ptr<common::Publisher<msg::DeformationState>>> out;
  std::vector<std::unique_ptr<common::StepInput<msg::ContactSet>>> in;
  const std::vector<std::uint32_t> ids = body_ids(steps);
  for (std::size_t b = 0; b < steps.size(); ++b) {
    out.push_back(std::make_unique<common::Publisher<msg::DeformationState>>(
        participant, common::lockstep_output_qos<msg::DeformationState>()));
    in.push_back(std::make_unique<common::StepInput<msg::ContactSet>>(
        participant, common::body_instance<msg::ContactSet>(ids, b, /*strays=*/false)));
  }
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
    const auto s = common::producer_step_for(k, haptic_steps);
    for (std::size_t b = 0; b < steps.size(); ++b) {
      ServiceStep& fem_step = *steps[b];
      if (s) {
        const msg::ContactSet* set = in[b]->wait(*s, 60s);
        if (set == nullptr) {
          std::fprintf(
              stderr, "fahr_fem_service: ContactSet of body '%s' of haptic step %llu never came\n",
              fem_step.setup().scene_body->name.c_str(), static_cast<unsigned long long>(*s));
          return 1;
        }
        fem_step.take(*set, set->header().seq());
      }
      fem_step.step();
      fem_step.state().header().sim_step(k);
      fem_step.state().header().sim_time_ns(static_cast<std::int64_t>(k) * base.count());
      out[b]->write(fem_step.state());
      hash.add(fem_step.state());
    }
    record(recorder, steps, k, t0, c0);
    client.complete_through(k + fem_steps - 1, hash.value());
  }
  return 0;
}

void append_metrics(const BodySteps& steps, std::vector<std::pair<std::string, double>>& out) {
  if (steps.size() == 1) {
    steps.front()->metrics(out);
    return;
  }
  for (const auto& step : steps) {
    const std::size_t first = out.size();
    step->metrics(out);
    for (std::size_t i = first; i < out.size(); ++i)
      out[i].first = step->setup().scene_body->name + "/" + out[i].first;
  }
}

void take_errors(BodySteps& steps, std::vector<std::string>& errors) {
  for (auto& step : steps) {
    const std::size_t first = errors.size();
    step->take_errors(errors);
    if (steps.size() == 1) continue;
    for (std::size_t i = first; i < errors.size(); ++i)
      errors[i] = "body '" + step->setup().scene_body->name + "': " + errors[i];
  }
}

namespace {

std::string field_sources(const FemBodySetup& setup) {
  std::vector<const runtime::RigidField*> fields;
  for (const auto& anatomy : setup.anatomy) fields.push_back(&anatomy->field());
  return runtime::describe_field_sources(fields);
}

}  // namespace

void print_start_lines(const common::Participant& participant, const BodySteps& steps,
                       const scene::Scene& scene, bool lockstep) {
  for (const auto& step : steps) {
    const FemBodySetup& setup = step->setup();
    std::printf(
        "fahr_fem_service: %s, body '%s' (%zu nodes, %zu tets, %zu fixed, %zu spheres, layout "
        "0x%016llx), %.0f Hz, %s, %s\n",
        std::string(common::vendor_name(participant.vendor())).c_str(),
        setup.scene_body->name.c_str(), setup.mesh.node_count(), setup.mesh.tet_count(),
        setup.fixed_nodes.size(), setup.links.size(),
        static_cast<unsigned long long>(setup.layout_fingerprint), scene.rates.fem_hz,
        lockstep ? "lockstep" : "realtime", field_sources(setup).c_str());
  }
}

namespace {

// What a factorisation not done at its latency cost: the step waited for it
// (lockstep), or the factor in use lagged for that many more steps.
std::string late_install(const fem::Body& body) {
  if (body.settings().solver.factor_install == fem::FactorInstall::kWait) return "waited for";
  return "up to " + std::to_string(body.most_steps_late()) + " steps went on without one, " +
         std::to_string(body.overdue_waits()) + " waited for after ten latencies";
}

}  // namespace

void print_end_lines(const BodySteps& steps) {
  for (const auto& step : steps) {
    const ServiceStep& fem_step = *step;
    const std::string body =
        steps.size() > 1 ? "body '" + fem_step.setup().scene_body->name + "': " : "";
    std::printf(
        "fahr_fem_service: %s%llu steps, stale contact sets %llu (a newer set followed %llu), "
        "refused (another sphere layout) %llu, max inverted elements %llu, resets after "
        "divergence %llu, steps shortened by the line search %llu, factorisations not done at "
        "their latency %llu (%s), spheres' W columns solved on the factorisation's thread "
        "%llu\n",
        body.c_str(), static_cast<unsigned long long>(fem_step.setup().body->step_index()),
        static_cast<unsigned long long>(fem_step.stale_sets()),
        static_cast<unsigned long long>(fem_step.stale_sets_followed()),
        static_cast<unsigned long long>(fem_step.layout_check().refused()),
        static_cast<unsigned long long>(fem_step.inverted_max()),
        static_cast<unsigned long long>(fem_step.divergence_resets()),
        static_cast<unsigned long long>(fem_step.shortened_steps()),
        static_cast<unsigned long long>(fem_step.setup().body->late_factorisations()),
        late_install(*fem_step.setup().body).c_str(),
        static_cast<unsigned long long>(fem_step.setup().body->compliance_refreshes_adopted()));
    const ServiceStep::SlowestStep& slow = fem_step.slowest_step();
    std::printf(
        "fahr_fem_service: %sslowest step %.1f ms (step %llu): refactorised %s, W block solved "
        "%s, tool contacts %zu, projection sweeps %d, anatomy rounds %d, nodes moved out of the "
        "anatomy %d, inverted tets %d\n",
        body.c_str(), 1e-6 * static_cast<double>(slow.wall_ns),
        static_cast<unsigned long long>(slow.step), slow.refactorised ? "yes" : "no",
        slow.compliance_solved ? "yes" : "no", slow.tool_contacts, slow.projection_sweeps,
        slow.anatomy_rounds, slow.anatomy_nodes, slow.inverted_elements);
  }
}

}  // namespace fahr::fem_service
