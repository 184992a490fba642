// fahr_stack_sim_run: the whole loop (gateway with a simulated hand, haptic
// service, FEM service) in lockstep in this process (sim/stack_sim)
// for a number of simulated seconds; prints each service's output hash as
// fahr_lockstep_clock does for the same run over DDS, and a few figures.
// Equal hashes show that the in-process run is the distributed one.
//
//   fahr_stack_sim_run [--scene FILE] [--script intubation|overshoot] [--collision aist|triangle]
//                      [--stiffening C20/C10] [--volume-floor R] [--w-normals N] [--seconds 4]
//
// --stiffening: the tongue's compression stiffening, the Yeoh ratio C20/C10
// (libs/fem compression_stiffening.h; 0: off), instead of the scene's.
// --w-normals N: W along the ContactSet's normals for N spheres (the
// scene's solver.compliance_columns: normals), with rows by free depth.
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <vector>

#include "deformation_statePubSubTypes.h"
#include "fahr/cli/cli.h"
#include "fahr/common/cdr_bytes.h"
#include "fahr/common/solver_threads.h"
#include "fahr/common/tool_row_forces.h"
#include "fahr/scene/load_scene.h"
#include "fahr/stack_sim/stack_sim.h"

namespace {

// Where the FEM step thread's CPU goes: per part, its median and p99 over
// all steps and its mean over the slowest 1 % of steps (those at or above
// the step thread's p99), in the order a step runs them.
void print_fem_step_parts(const std::vector<fahr::stack_sim::StackSim::FemStepCpu>& steps) {
  if (steps.empty()) return;
  std::vector<std::int64_t> thread;
  thread.reserve(steps.size());
  for (const auto& s : steps) thread.push_back(s.thread_ns);
  std::sort(thread.begin(), thread.end());
  const std::int64_t slow =
      thread[static_cast<std::size_t>(0.99 * static_cast<double>(thread.size() - 1))];
  struct Part {
    const char* name;
    std::int64_t fahr::fem::StepParts::*field;
  };
  const Part parts[] = {
      {"forces", &fahr::fem::StepParts::forces_ns},
      {"system", &fahr::fem::StepParts::system_ns},
      {"solve", &fahr::fem::StepParts::solve_ns},
      {"line search", &fahr::fem::StepParts::line_search_ns},
      {"compliance", &fahr::fem::StepParts::compliance_ns},
      {"projection", &fahr::fem::StepParts::projection_ns},
      {"supports", &fahr::fem::StepParts::supports_ns},
  };
  std::vector<std::int64_t> values(steps.size());
  std::size_t slow_count = 0;
  double slow_thread = 0.0;
  for (const auto& s : steps) {
    if (s.thread_ns >= slow) {
      ++slow_count;
      slow_thread += static_cast<double>(s.thread_ns);
    }
  }
  std::printf(
      "stack_sim: FEM step thread CPU by part, ms: median, p99 over %zu steps; mean over the %zu "
      "slowest (thread >= %.2f ms, mean %.2f)\n",
      steps.size(), slow_count, 1e-6 * static_cast<double>(slow),
      1e-6 * slow_thread / static_cast<double>(slow_count));
  double slow_parts = 0.0;
  for (const Part& part : parts) {
    double slow_sum = 0.0;
    for (std::size_t i = 0; i < steps.size(); ++i) {
      values[i] = steps[i].parts.*part.field;
      if (steps[i].thread_ns >= slow) slow_sum += static_cast<double>(values[i]);
    }
    std::sort(values.begin(), values.end());
    const auto at = [&values](double q) {
      return 1e-6 *
             static_cast<double>(
                 values[static_cast<std::size_t>(q * static_cast<double>(values.size() - 1))]);
    };
    slow_parts += slow_sum;
    std::printf("stack_sim: FEM step part %-11s median %.3f p99 %.3f slowest %.3f\n", part.name,
                at(0.5), at(0.99), 1e-6 * slow_sum / static_cast<double>(slow_count));
  }
  std::printf(
      "stack_sim: FEM step part %-11s slowest %.3f (the state's message, the set's intake)\n",
      "other", 1e-6 * (slow_thread - slow_parts) / static_cast<double>(slow_count));
}

}  // namespace

// A function-try-block: what the set-up before the inner try throws ends in a message too.
int main(int argc, char** argv) try {
  fahr::common::run_solver_libraries_on_one_thread(argv);
  using namespace fahr;
  fahr::cli::App app{"fahr in-process lockstep run"};
  std::string scene_path = FAHR_SOURCE_DIR "/deployment/scenes/neonatal_intubation.yaml";
  std::string script = "intubation";
  double seconds = 4.0;
  app.add_option("--scene", scene_path, "scene file");
  app.add_option("--script", script, "the simulated hand's script")
      ->check(
          fahr::cli::IsMember({std::begin(device::kScriptNames), std::end(device::kScriptNames)}));
  std::string collision = "aist";
  app.add_option("--collision", collision, "the haptic service's collision method")
      ->check(fahr::cli::IsMember({"aist", "triangle"}));
  double stiffening = -1.0;
  app.add_option("--stiffening", stiffening,
                 "the tongue's compression stiffening, Yeoh C20/C10; 0: off (default: the scene's)")
      ->check(fahr::cli::Range(0.0, 100.0));
  double volume_floor = -1.0;
  app.add_option("--volume-floor", volume_floor,
                 "no tet ends a FEM step below this share of its rest volume "
                 "(solver.volume_floor_ratio); 0: off "
                 "(default: the scene's)")
      ->check(fahr::cli::Range(0.0, 0.9));
  int w_normals = 0;
  app.add_option("--w-normals", w_normals,
                 "W along the normals for this many spheres (solver.compliance_columns: normals, "
                 "max_candidate_contacts); 0: the scene's")
      ->check(fahr::cli::Range(0, 64));
  app.add_option("--seconds", seconds, "simulated time, s")->check(fahr::cli::Range(0.001, 3600.0));
  if (const auto exit = app.parse(argc, argv)) return *exit;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  try {
    stack_sim::StackOptions options;
    device::script_by_name(script, options.script);  // the option checks the name
    options.collision = collision == "triangle" ? haptic_service::CollisionMethod::kTriangle
                                                : haptic_service::CollisionMethod::kAist;
    auto scene = std::make_shared<scene::Scene>(*scene::load_scene(scene_path));
    if (volume_floor >= 0.0) scene->solver.volume_floor_ratio = volume_floor;
    for (auto& body : scene->bodies) {
      if (body.deformable && stiffening >= 0.0)
        body.deformable->material.yeoh_c20_over_c10 = stiffening;
    }
    if (w_normals > 0) {
      scene->solver.compliance_columns = scene::ComplianceColumns::kNormals;
      scene->solver.max_candidate_contacts = w_normals;
    }
    stack_sim::StackSim sim(scene, options);
    const auto steps = static_cast<std::uint64_t>(std::llround(seconds * 1000.0));
    const auto start = std::chrono::steady_clock::now();
    double peak_force = 0.0;
    // Rendering smoothness: the commanded force's change from one tick to
    // the next, N (the fault test's 0.1 N rule is for fault handling; here
    // it counts ordinary rendering's steps).
    Eigen::Vector3d previous_force = Eigen::Vector3d::Zero();
    double largest_step = 0.0;
    std::uint64_t steps_over_tenth = 0;
    std::uint64_t largest_step_tick = 0;
    // The contact solve's share of a tick: PGS row visits x rows (the cost
    // in k-long dot products) and solves per tick, and how many hit the cap.
    std::vector<double> pgs_cost;
    std::vector<double> pgs_solves;
    std::vector<double> rows;
    std::uint64_t unconverged = 0;
    std::vector<std::uint8_t> state_bytes;  // one DeformationState's CDR
    std::vector<double> state_sizes;
    // Wall time of the tick's phases (a preempted tick shows in the tail).
    std::vector<double> tissue_query_us, anatomy_query_us, response_us;
    std::vector<double> load_us, move_us, output_us;  // the response's parts
    std::vector<double> query_nodes, query_spheres, query_contacts,
        query_inside;  // the AIST query's work per tick
    // The tissue query on the first tick of a FEM state (every sphere moved:
    // the floors of the last query bound less, and the refit left the data
    // cold) and on the ticks after it (only the blade moved).
    std::vector<double> query_new_state_us, query_same_state_us, spheres_new_state,
        spheres_same_state;
    std::uint64_t states_seen = sim.haptic().metrics().snapshots.load(std::memory_order_relaxed);
    // Per deformable body: ticks whose ContactSet held a tool contact (active
    // or frozen, not a candidate) and the most such contacts in one set.
    std::vector<std::uint64_t> touched_ticks(sim.body_count(), 0);
    std::vector<std::size_t> most_touching(sim.body_count(), 0);
    // The largest sum of the tool rows' forces sent on one tick, and their
    // resultant then: far apart, the rows squeeze the tissue from both faces
    // of the blade (docs/design/force-aware-decision.md, a pinch).
    double largest_row_sum = 0.0, resultant_at_largest = 0.0;
    for (std::uint64_t k = 0; k < steps; ++k) {
      sim.step();
      common::ToolRowForces rows_sent;
      for (std::size_t b = 0; b < sim.body_count(); ++b) {
        const common::ToolRowForces body_rows = common::tool_row_forces(sim.contacts(b));
        rows_sent.resultant_n += body_rows.resultant_n;
        rows_sent.magnitudes_n += body_rows.magnitudes_n;
        const auto& contacts = sim.contacts(b).contacts();
        const auto touching = static_cast<std::size_t>(
            std::count_if(contacts.begin(), contacts.end(), [](const msg::Contact& c) {
              return c.kind() != msg::CONTACT_OBSTACLE && c.state() != msg::CONSTRAINT_CANDIDATE;
            }));
        if (touching > 0) ++touched_ticks[b];
        most_touching[b] = std::max(most_touching[b], touching);
      }
      if (rows_sent.magnitudes_n > largest_row_sum) {
        largest_row_sum = rows_sent.magnitudes_n;
        resultant_at_largest = rows_sent.resultant_n.norm();
      }
      const auto& report = sim.haptic().response().report();
      pgs_cost.push_back(static_cast<double>(report.pgs_work.row_visits) *
                         static_cast<double>(report.load.rows));
      pgs_solves.push_back(report.pgs_work.solves);
      rows.push_back(static_cast<double>(report.load.rows));
      unconverged += report.pgs_work.unconverged;
      const auto& phases = sim.haptic().last_phases();
      tissue_query_us.push_back(phases.tissue_query_us);
      anatomy_query_us.push_back(phases.anatomy_query_us);
      response_us.push_back(phases.response_us);
      load_us.push_back(report.load_us);
      move_us.push_back(report.move_us);
      output_us.push_back(report.output_us);
      query_nodes.push_back(phases.tissue_query.nodes_visited);
      query_spheres.push_back(phases.tissue_query.spheres_tested);
      query_contacts.push_back(phases.tissue_query.contacts);
      query_inside.push_back(phases.tissue_query.spheres_inside);
      const std::uint64_t states = sim.haptic().metrics().snapshots.load(std::memory_order_relaxed);
      (states != states_seen ? query_new_state_us : query_same_state_us)
          .push_back(phases.tissue_query_us);
      (states != states_seen ? spheres_new_state : spheres_same_state)
          .push_back(phases.tissue_query.spheres_tested);
      states_seen = states;
      if (sim.fem_stepped() && sim.body().step_index() % 20 == 1) {
        // What one DeformationState of the tongue puts on the wire (CDR as
        // sent), sampled every 20th FEM step.
        common::encode_cdr<msg::DeformationStatePubSubType>(sim.fem().state(), state_bytes);
        state_sizes.push_back(static_cast<double>(state_bytes.size()));
      }
      const auto& f = sim.command().force_n();
      peak_force = std::max(peak_force, std::sqrt(f.x() * f.x() + f.y() * f.y() + f.z() * f.z()));
      const Eigen::Vector3d force(f.x(), f.y(), f.z());
      const double step = (force - previous_force).norm();
      if (step > 0.1) ++steps_over_tenth;
      if (step > largest_step) {
        largest_step = step;
        largest_step_tick = k;
      }
      previous_force = force;
    }
    const double wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf(
        "stack_sim: %llu steps, %.2f s wall (%.2fx real time), peak |F| %.3f N; FEM: %llu steps, "
        "stale "
        "contact sets %llu, max inverted elements %llu, resets after divergence %llu, steps "
        "shortened by the line search %llu\n",
        static_cast<unsigned long long>(steps), wall_s, seconds / wall_s, peak_force,
        static_cast<unsigned long long>(sim.body().step_index()),
        static_cast<unsigned long long>(sim.fem().stale_sets()),
        static_cast<unsigned long long>(sim.fem().inverted_max()),
        static_cast<unsigned long long>(sim.fem().divergence_resets()),
        static_cast<unsigned long long>(sim.fem().shortened_steps()));
    std::printf(
        "stack_sim: commanded force step per tick: largest %.3f N (tick %llu), ticks over 0.1 N "
        "%llu\n",
        largest_step, static_cast<unsigned long long>(largest_step_tick),
        static_cast<unsigned long long>(steps_over_tenth));
    std::printf(
        "stack_sim: tool rows' forces on a tick: largest sum %.3f N, their resultant then %.3f N\n",
        largest_row_sum, resultant_at_largest);
    std::printf(
        "stack_sim: FEM anatomy: nodes let back through a bone %llu, node-steps beyond a bone "
        "%llu\n",
        static_cast<unsigned long long>(sim.fem().anatomy_returned()),
        static_cast<unsigned long long>(sim.fem().anatomy_beyond_steps()));
    for (std::size_t b = 0; b < sim.body_count() && sim.body_count() > 1; ++b) {
      const double moved = sim.largest_node_motion_m(b);
      std::printf(
          "stack_sim: body '%s': ticks with tool contacts %llu, most in one set %zu, largest node "
          "motion %.2f mm, ContactSets refused: layout %llu, unknown sphere %llu; max inverted "
          "elements %llu, resets %llu\n",
          sim.fem(b).setup().scene_body->name.c_str(),
          static_cast<unsigned long long>(touched_ticks[b]), most_touching[b], 1e3 * moved,
          static_cast<unsigned long long>(sim.fem(b).layout_check().refused()),
          static_cast<unsigned long long>(sim.fem(b).unknown_sphere_sets()),
          static_cast<unsigned long long>(sim.fem(b).inverted_max()),
          static_cast<unsigned long long>(sim.fem(b).divergence_resets()));
    }
    const auto& cpu = sim.haptic_tick_cpu();
    const auto& fem_cpu = sim.fem_step_cpu();
    // The tissue-fidelity lines, as scripts grep them: over the whole run.
    const auto& hm = sim.haptic().metrics();
    const auto total = [](const auto& a) {
      return static_cast<unsigned long long>(a.load(std::memory_order_relaxed));
    };
    std::printf("tissue rows solved: %llu\n", total(hm.tissue_rows_total));
    std::printf("rows without tissue compliance: %llu\n", total(hm.rows_without_compliance));
    std::printf(
        "stack_sim: of the rows without tissue compliance, touching the blade: %llu (the "
        "others are candidates within the margin)\n",
        total(hm.rows_without_compliance_touching));
    std::printf("rows dropped: %llu\n", total(hm.rows_dropped));
    std::printf(
        "stack_sim: FEM refactorisations %llu, compliance blocks solved %llu, reused %llu; "
        "spheres' W columns solved on the factorisation's thread %llu\n",
        static_cast<unsigned long long>(sim.fem().refactorisations()),
        static_cast<unsigned long long>(sim.fem().contact_step().compliance_solves()),
        static_cast<unsigned long long>(sim.fem().contact_step().compliance_reuses()),
        static_cast<unsigned long long>(sim.fem().setup().body->compliance_refreshes_adopted()));
    std::printf("stack_sim: %s\n", haptic_service::w_summary(sim.haptic().metrics()).c_str());
    std::printf("FEM step CPU ms median %.2f p99 %.2f max %.2f\n",
                1e-6 * static_cast<double>(fem_cpu.percentile(0.5).count()),
                1e-6 * static_cast<double>(fem_cpu.percentile(0.99).count()),
                1e-6 * static_cast<double>(fem_cpu.max().count()));
    const auto& thread_cpu = sim.fem_step_thread_cpu();
    std::printf(
        "stack_sim: FEM step thread CPU ms median %.2f p99 %.2f max %.2f; background "
        "factorisation CPU %.2f s, %.2f ms a step\n",
        1e-6 * static_cast<double>(thread_cpu.percentile(0.5).count()),
        1e-6 * static_cast<double>(thread_cpu.percentile(0.99).count()),
        1e-6 * static_cast<double>(thread_cpu.max().count()),
        1e-9 * static_cast<double>(sim.fem_background_cpu().count()),
        thread_cpu.count() == 0 ? 0.0
                                : 1e-6 * static_cast<double>(sim.fem_background_cpu().count()) /
                                      static_cast<double>(thread_cpu.count()));
    const fem::BackgroundCpu bg = sim.fem().setup().body->background_parts();
    const double jobs = bg.jobs == 0 ? 1.0 : static_cast<double>(bg.jobs);
    std::printf(
        "stack_sim: background factorisation CPU ms a job over %llu jobs: assembly %.2f, "
        "factorisation %.2f, W's columns %.2f\n",
        static_cast<unsigned long long>(bg.jobs), 1e-6 * static_cast<double>(bg.fill_ns) / jobs,
        1e-6 * static_cast<double>(bg.factor_ns) / jobs,
        1e-6 * static_cast<double>(bg.after_ns) / jobs);
    print_fem_step_parts(sim.fem_step_parts());
    const auto us = [](std::chrono::nanoseconds d) { return static_cast<double>(d.count()) / 1e3; };
    std::printf("stack_sim: haptic tick CPU us median %.0f p99 %.0f p99.9 %.0f max %.0f\n",
                us(cpu.percentile(0.5)), us(cpu.percentile(0.99)), us(cpu.percentile(0.999)),
                us(cpu.max()));
    const auto quantile = [](std::vector<double> v, double q) {
      if (v.empty()) return 0.0;
      const auto i = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
      std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(i), v.end());
      return v[i];
    };
    std::printf(
        "stack_sim: rows per tick p50 %.0f p99 %.0f max %.0f; PGS solves per tick p99 %.0f max "
        "%.0f; "
        "PGS row visits x rows p50 %.0f p99 %.0f p99.9 %.0f max %.0f; unconverged solves %llu\n",
        quantile(rows, 0.5), quantile(rows, 0.99), quantile(rows, 1.0), quantile(pgs_solves, 0.99),
        quantile(pgs_solves, 1.0), quantile(pgs_cost, 0.5), quantile(pgs_cost, 0.99),
        quantile(pgs_cost, 0.999), quantile(pgs_cost, 1.0),
        static_cast<unsigned long long>(unconverged));
    // A lab's link carries every body's state at the FEM's rate.
    const double fem_hz = sim.scene().rates.fem_hz;
    std::printf(
        "stack_sim: DeformationState bytes (tongue, CDR) median %.0f max %.0f; at %.0f Hz %.1f "
        "Mbit/s at the largest\n",
        quantile(state_sizes, 0.5), quantile(state_sizes, 1.0), fem_hz,
        8e-6 * fem_hz * quantile(state_sizes, 1.0));
    const auto print_phase = [&](const char* name, const std::vector<double>& wall_us) {
      std::printf("stack_sim: tick phase %-14s wall us p50 %.1f p99 %.1f p99.9 %.1f\n", name,
                  quantile(wall_us, 0.5), quantile(wall_us, 0.99), quantile(wall_us, 0.999));
    };
    print_phase("tissue query", tissue_query_us);
    print_phase("  new state", query_new_state_us);
    print_phase("  same state", query_same_state_us);
    print_phase("anatomy query", anatomy_query_us);
    print_phase("response", response_us);
    print_phase("  load", load_us);
    print_phase("  move", move_us);
    print_phase("  output", output_us);
    std::printf(
        "stack_sim: AIST query per tick: tree nodes p50 %.0f p99 %.0f, spheres tested p50 %.0f p99 "
        "%.0f, "
        "contacts p50 %.0f p99 %.0f max %.0f, centre inside p99 %.0f max %.0f\n",
        quantile(query_nodes, 0.5), quantile(query_nodes, 0.99), quantile(query_spheres, 0.5),
        quantile(query_spheres, 0.99), quantile(query_contacts, 0.5),
        quantile(query_contacts, 0.99), quantile(query_contacts, 1.0), quantile(query_inside, 0.99),
        quantile(query_inside, 1.0));
    std::printf(
        "stack_sim: AIST spheres tested on a new FEM state p50 %.0f p99 %.0f, on the same state "
        "p50 %.0f p99 %.0f\n",
        quantile(spheres_new_state, 0.5), quantile(spheres_new_state, 0.99),
        quantile(spheres_same_state, 0.5), quantile(spheres_same_state, 0.99));
    std::printf("lockstep_clock: hash device_gateway %016llx\n",
                static_cast<unsigned long long>(sim.gateway_hash()));
    std::printf("lockstep_clock: hash fem %016llx\n",
                static_cast<unsigned long long>(sim.fem_hash()));
    std::printf("lockstep_clock: hash haptic %016llx\n",
                static_cast<unsigned long long>(sim.haptic_hash()));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_stack_sim_run: %s\n", e.what());
    return 2;
  }
} catch (const std::exception& e) {
  std::fprintf(stderr, "fahr_stack_sim_run: %s\n", e.what());
  return 1;
}
