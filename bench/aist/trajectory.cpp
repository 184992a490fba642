// The scripted laryngoscope trajectory: the FEM tongue pressed by the Miller
// 1 blade, AIST and the triangle baseline interleaved in one process.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <memory>
#include <numeric>
#include <random>
#include <string>

#include "contact_metrics.h"
#include "fahr/collision/field_grid.h"
#include "fahr/collision/sphere_query.h"
#include "fahr/collision/sphere_tree.h"
#include "fahr/collision/triangle_baseline.h"
#include "fahr/layout_links/fem_links.h"
#include "fahr/sphere_layout/fill_spheres.h"
#include "node_metrics.h"
#include "sections.h"
#include "sphere_contact_set.h"
#include "stats.h"
#include "surface_contacts.h"

namespace fahr::aist_bench {
namespace {

using Clock = std::chrono::steady_clock;

struct Timings {
  std::vector<double> query_us, update_us, tick_us;
  std::vector<double> best_query_us;  // best of kRepeats runs of the same query
  std::vector<double> cpu_query_us;   // thread CPU time of the first run
  // Thread CPU time of the same query run again at once: its data still in
  // cache, as on a haptic core that runs nothing else; the other figures
  // carry the misses the other methods' data cause in between.
  std::vector<double> warm_cpu_us;
};

// Each query is run this many times on the same state and pose; the best
// time shows the method's own cost on a shared machine, where the first run
// (the one the tick uses) also carries preemption by other processes.
constexpr int kRepeats = 3;

// One way of running the AIST query; every variant sees the same states and poses.
struct Variant {
  const char* name;
  collision::QuerySettings settings;
  const collision::FieldGrid* grid;  // RigidBody::grid
  collision::PrePenetrationMemory memory;
  collision::ContactBuffer buffer;
  Timings timings;
  double nodes_sum = 0.0, tested_sum = 0.0, narrow_sum = 0.0;
  std::uint32_t nodes_max = 0, tested_max = 0, narrow_max = 0;
  std::size_t contacts = 0;  // touching, summed over ticks
};

// The contacts two variants disagree on in one tick: a sphere touching in
// one and not the other, or a depth differing by more than tolerance_m.
// largest_m: the largest depth difference of a sphere touching in both.
std::size_t disagreements(const collision::ContactBuffer& a, const collision::ContactBuffer& b,
                          double tolerance_m, double& largest_m) {
  std::size_t count = 0;
  for (const auto& x : a) {
    if (x.candidate) continue;
    bool same = false;
    for (const auto& y : b) {
      if (y.sphere_id != x.sphere_id || y.candidate) continue;
      largest_m = std::max(largest_m, std::abs(y.depth_m - x.depth_m));
      same = same || std::abs(y.depth_m - x.depth_m) <= tolerance_m;
    }
    count += same ? 0 : 1;
  }
  for (const auto& y : b) {
    if (y.candidate) continue;
    bool found = false;
    for (const auto& x : a) found = found || (x.sphere_id == y.sphere_id && !x.candidate);
    count += found ? 0 : 1;
  }
  return count;
}

void print_timing_row(const char* name, const Timings& t) {
  std::printf(
      "| %s | %.1f | %.1f | %.1f | %.1f / %.1f / %.1f | %.1f / %.1f / %.1f | %.1f / %.1f / %.1f | "
      "%.1f | %.1f | %.1f | %.1f | %.1f |\n",
      name, percentile(t.query_us, 50), percentile(t.query_us, 99), percentile(t.query_us, 99.9),
      percentile(t.cpu_query_us, 50), percentile(t.cpu_query_us, 99),
      percentile(t.cpu_query_us, 99.9), percentile(t.best_query_us, 50),
      percentile(t.best_query_us, 99), percentile(t.best_query_us, 99.9),
      percentile(t.warm_cpu_us, 50), percentile(t.warm_cpu_us, 99), percentile(t.warm_cpu_us, 99.9),
      percentile(t.update_us, 50), percentile(t.update_us, 99.9), percentile(t.tick_us, 50),
      percentile(t.tick_us, 99), percentile(t.tick_us, 99.9));
}

}  // namespace

sphere_layout::FillSettings trajectory_fill(const Options& options) {
  sphere_layout::FillSettings fill;
  fill.weight_spread = options.weight_spread;
  fill.hugging_weight_spread = std::min(fill.hugging_weight_spread, options.weight_spread);
  fill.hugging_tolerance_m = options.hugging_tolerance_m;
  fill.hugging_radius_fraction = options.hugging_radius_fraction;
  fill.hugging_anchor_depth_factor = options.anchor_depth_factor;
  fill.anchor_gap_m = options.anchor_gap_m;
  fill.max_spheres = options.max_spheres;
  return fill;
}

collision::QuerySettings trajectory_query(const Options& options) {
  collision::QuerySettings settings;
  settings.contact_skin_m = options.skin_m;
  settings.candidate_margin_m = kCandidateMarginM;
  settings.approach_margin_m = options.approach_margin_m;
  settings.surface_probe = options.surface_probe;
  return settings;
}

void trajectory_table(const Scene& scene, const Options& options) {
  const sphere_layout::FillSettings fill = trajectory_fill(options);
  const sphere_layout::SphereLayout layout = sphere_layout::fill_spheres(scene.tongue, fill);
  const fem::SphereLinks links = layout_links::to_fem_links(layout, options.skin_m);
  auto body = make_tongue_body(scene);
  std::vector<double> rest;
  for (const auto& p : scene.tongue.rest_positions())
    rest.insert(rest.end(), {p.x(), p.y(), p.z()});
  collision::SphereState state = options.stretch_radius ? collision::SphereState(layout, rest)
                                                        : collision::SphereState(layout);
  collision::SphereTree tree(layout);
  const collision::FieldGrid blade_grid(scene.blade_sdf);
  const collision::QuerySettings exact_settings = trajectory_query(options);
  collision::QuerySettings grid_settings = exact_settings;
  grid_settings.exact_narrow_phase = false;
  // The first two are the AIST as the library is meant to be used (with the
  // blade's FieldGrid); the other two read the field's own grid, the path
  // without a FieldGrid, to measure what the copy changes in one run.
  // A deque: a Variant holds buffers and is neither copied nor moved.
  std::deque<Variant> variants;
  variants.push_back({"AIST, exact narrow phase",
                      exact_settings,
                      &blade_grid,
                      collision::PrePenetrationMemory(layout.size()),
                      collision::ContactBuffer(4096),
                      {}});
  variants.push_back({"AIST, grid narrow phase",
                      grid_settings,
                      &blade_grid,
                      collision::PrePenetrationMemory(layout.size()),
                      collision::ContactBuffer(4096),
                      {}});
  variants.push_back({"AIST, exact, field's own grid",
                      exact_settings,
                      nullptr,
                      collision::PrePenetrationMemory(layout.size()),
                      collision::ContactBuffer(4096),
                      {}});
  variants.push_back({"AIST, grid, field's own grid",
                      grid_settings,
                      nullptr,
                      collision::PrePenetrationMemory(layout.size()),
                      collision::ContactBuffer(4096),
                      {}});
  const int methods = static_cast<int>(variants.size()) + 1;  // the baseline last
  // Contacts the FieldGrid changes: the same sphere touching in both, depth
  // within 10 nm (its single-precision values are within a few nm).
  constexpr double kSameDepthM = 1e-8;
  std::size_t exact_changed = 0, grid_changed = 0;
  double exact_largest_m = 0.0, grid_largest_m = 0.0;
  collision::RigidBody blade{1, &scene.blade_sdf, Eigen::Isometry3d::Identity()};
  collision::TriangleBaseline baseline(scene.boundary, scene.surface_to_node, scene.blade);
  std::vector<collision::TriangleContact> base_contacts;
  base_contacts.reserve(8192);
  fem::ContactSet set;
  set.contacts.reserve(4096);
  ContactMetrics metrics(scene), grid_metrics(scene);
  NodeMetrics node_metrics(scene), grid_node_metrics(scene);
  // The reference driver, built only when it drives (its face points cost
  // set-up at a high subdivision).
  std::unique_ptr<SurfaceContacts> reference_driver;
  if (options.reference_driven)
    reference_driver = std::make_unique<SurfaceContacts>(scene, options.driver_subdivision);
  const collision::ContactBuffer& buffer = variants[0].buffer;  // drives the FEM in the closed loop

  Timings base;
  std::vector<int> order(static_cast<std::size_t>(methods));
  std::iota(order.begin(), order.end(), 0);
  std::mt19937 shuffler(5);  // fixed seed: the same orders every run
  std::size_t fem_steps = 0, max_aist_contacts = 0, max_base_contacts = 0, overflows = 0;
  double fem_ms = 0.0;
  for (int tick = 0; tick < options.ticks; ++tick) {
    const double s = static_cast<double>(tick) / (options.ticks - 1);
    blade.world_from_body = blade_pose(scene, s, options.lever_depth_m);
    const bool new_state = tick % options.fem_every == 0;
    const bool aist_first = tick % 2 == 0;  // interleaved: neither always runs on a warm cache
    double aist_update = 0.0, base_update = 0.0;
    if (new_state && options.reference_driven) {
      reference_driver->fill(*body, blade.world_from_body, set);
      const auto fem_start = Clock::now();
      body->step(&set, &reference_driver->links());
      fem_ms += elapsed_us(fem_start) / 1e3;
      ++fem_steps;
    } else if (new_state) {
      fill_sphere_contacts(buffer, body->step_index(), set);
      const auto fem_start = Clock::now();
      body->step(&set, &links);
      fem_ms += elapsed_us(fem_start) / 1e3;
      ++fem_steps;
    }
    if (new_state) {
      const auto x = body->positions_m();
      for (int turn = 0; turn < 2; ++turn) {
        const auto start = Clock::now();
        if ((turn == 0) == aist_first) {
          state.update(layout, x);
          tree.refit(state);
          aist_update = elapsed_us(start);
        } else {
          baseline.update(x);
          base_update = elapsed_us(start);
        }
      }
      for (auto& v : variants) v.timings.update_us.push_back(aist_update);
      base.update_us.push_back(base_update);
    }
    std::vector<double> query(methods, 0.0), best(methods, 1e300);
    for (int repeat = 0; repeat < kRepeats; ++repeat) {
      // A fresh order every round: each method follows each other one (whose
      // data evicts its cache lines) equally often. A rotation would always put
      // the same method right after the baseline.
      std::shuffle(order.begin(), order.end(), shuffler);
      for (int turn = 0; turn < methods; ++turn) {
        const int who = order[static_cast<std::size_t>(turn)];
        const double cpu_start = thread_cpu_us();
        const auto start = Clock::now();
        if (who < static_cast<int>(variants.size())) {
          Variant& v = variants[static_cast<std::size_t>(who)];
          blade.grid = v.grid;
          v.buffer.clear();
          const auto stats =
              collision::query_spheres(tree, state, blade, v.settings, v.memory, v.buffer);
          const double t = elapsed_us(start);
          best[who] = std::min(best[who], t);
          if (repeat == kRepeats - 1) {
            v.buffer.clear();
            const double warm_start = thread_cpu_us();
            collision::query_spheres(tree, state, blade, v.settings, v.memory, v.buffer);
            v.timings.warm_cpu_us.push_back(thread_cpu_us() - warm_start);
          }
          if (repeat > 0) continue;
          v.timings.cpu_query_us.push_back(thread_cpu_us() - cpu_start);
          query[who] = t;
          overflows += stats.overflowed ? 1 : 0;
          v.tested_sum += stats.spheres_tested;
          v.narrow_sum += stats.exact_queries;
          v.nodes_sum += stats.nodes_visited;
          v.nodes_max = std::max(v.nodes_max, stats.nodes_visited);
          v.tested_max = std::max(v.tested_max, stats.spheres_tested);
          v.narrow_max = std::max(v.narrow_max, stats.exact_queries);
        } else {
          baseline.collide(blade.world_from_body, base_contacts);
          const double t = elapsed_us(start);
          best[who] = std::min(best[who], t);
          if (repeat == kRepeats - 1) {
            const double warm_start = thread_cpu_us();
            baseline.collide(blade.world_from_body, base_contacts);
            base.warm_cpu_us.push_back(thread_cpu_us() - warm_start);
          }
          if (repeat == 0) {
            query[who] = t;
            base.cpu_query_us.push_back(thread_cpu_us() - cpu_start);
          }
        }
      }
    }
    for (int who = 0; who < methods; ++who) {
      Timings& t = who < static_cast<int>(variants.size())
                       ? variants[static_cast<std::size_t>(who)].timings
                       : base;
      t.best_query_us.push_back(best[who]);
      t.query_us.push_back(query[who]);
      t.tick_us.push_back(query[who] +
                          (who < static_cast<int>(variants.size()) ? aist_update : base_update));
    }
    exact_changed +=
        disagreements(variants[0].buffer, variants[2].buffer, kSameDepthM, exact_largest_m);
    grid_changed +=
        disagreements(variants[1].buffer, variants[3].buffer, kSameDepthM, grid_largest_m);
    for (auto& v : variants) {
      for (const auto& c : v.buffer) v.contacts += c.candidate ? 0 : 1;
    }
    grid_metrics.add_tick(variants[1].buffer, state, base_contacts, blade.world_from_body,
                          body->positions_m());
    grid_node_metrics.add_tick(variants[1].buffer, state, base_contacts, blade.world_from_body,
                               body->positions_m());
    std::size_t touching = 0;
    for (const auto& c : buffer) touching += c.candidate ? 0 : 1;
    max_aist_contacts = std::max(max_aist_contacts, touching);
    max_base_contacts = std::max(max_base_contacts, base_contacts.size());
    metrics.add_tick(buffer, state, base_contacts, blade.world_from_body, body->positions_m());
    node_metrics.add_tick(buffer, state, base_contacts, blade.world_from_body, body->positions_m());
  }

  const std::string driver_text =
      !reference_driver ? std::string()
      : options.driver_subdivision == 1
          ? std::string("every boundary node (surface_contacts.h), neither detector")
          : std::to_string(reference_driver->point_count()) +
                " boundary points, the nodes and each face at subdivision " +
                std::to_string(options.driver_subdivision) +
                " (surface_contacts.h), neither detector";
  std::printf(
      "\n## %s: Miller 1 pressing and levering the FEM tongue (%d ticks at 1 kHz, FEM every %d "
      "ticks, contact skin %.2f mm, candidate margin %.2f mm)\n\n",
      options.reference_driven ? "Detection only (the FEM driven by its boundary points' contacts)"
                               : "Trajectory",
      options.ticks, options.fem_every, options.skin_m * 1e3, kCandidateMarginM * 1e3);
  std::printf(
      "Layout: %zu spheres (%zu grid level 0, %zu level 1, %zu hugging; %zu with a surface anchor, "
      "anchor gap %.2f mm, surface probe: %s), ratio %.0f, levels %d, weight spread %.2f (hugging "
      "%.2f), radius rule: %s. "
      "FEM (fahr::fem, corotational, implicit Euler, Algorithm 1 projection of %s): "
      "%zu steps, %.2f ms per step. Contacts per tick at most: AIST %zu, baseline %zu; buffer "
      "overflows: %zu. "
      "Rebuilds after construction: AIST tree %llu, baseline tree %llu.\n\n",
      layout.size(), layout.count_at_level(0), layout.count_at_level(1),
      layout.count(sphere_layout::SphereOrigin::kHugging), layout.anchor_count(),
      fill.anchor_gap_m * 1e3,
      options.surface_probe == collision::QuerySettings::SurfaceProbe::kAnchor
          ? "fixed anchor"
          : "face point under the contact",
      fill.volume_ratio, fill.refinement_levels, fill.weight_spread, fill.hugging_weight_spread,
      options.stretch_radius ? "smallest stretch" : "volume",
      options.reference_driven ? driver_text.c_str() : "the AIST contacts", fem_steps,
      fem_ms / static_cast<double>(fem_steps), max_aist_contacts, max_base_contacts, overflows,
      static_cast<unsigned long long>(tree.rebuild_count()),
      static_cast<unsigned long long>(baseline.rebuild_count()));
  std::printf(
      "| method | query median (us) | query p99 | query p99.9 | query thread CPU: median / p99 / "
      "p99.9 (us) | best of %d: median / p99 / p99.9 (us) | warm rerun thread CPU: median / p99 / "
      "p99.9 (us) | update+refit median (us) | update+refit p99.9 | tick median (us) | tick p99 | "
      "tick p99.9 |\n",
      kRepeats);
  std::printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  for (const auto& v : variants) print_timing_row(v.name, v.timings);
  print_timing_row("baseline (Bullet GImpact trees + vertex-face)", base);
  const double n = static_cast<double>(options.ticks);
  std::printf(
      "\nPer AIST query on average (exact, grid): %.0f / %.0f tree nodes visited, %.0f / %.0f "
      "spheres tested, "
      "%.0f / %.0f narrow-phase spheres (at most %u nodes, %u spheres tested, %u narrow-phase). "
      "The blade's FieldGrid: %.1f MB, storage rounding %.2g mm. Touching "
      "contacts that differ with and without it (sphere touching in one only, or depth apart by "
      "more than "
      "10 nm), over %zu / %zu: exact %zu, grid %zu; largest depth difference of a sphere touching "
      "in both: exact "
      "%.2g mm, grid %.2g mm.\n",
      variants[0].nodes_sum / n, variants[1].nodes_sum / n, variants[0].tested_sum / n,
      variants[1].tested_sum / n, variants[0].narrow_sum / n, variants[1].narrow_sum / n,
      variants[1].nodes_max, variants[1].tested_max, variants[1].narrow_max,
      4.0 * static_cast<double>(scene.blade_sdf.grid_dimensions().prod()) / 1e6,
      blade_grid.storage_error_m() * 1e3, variants[2].contacts, variants[3].contacts, exact_changed,
      grid_changed, exact_largest_m * 1e3, grid_largest_m * 1e3);
  for (const auto& v : variants) {
    const Timings& t = v.timings;
    std::printf(
        "Speed-up (baseline / %s): thread CPU median %.1fx, p99.9 %.1fx; warm rerun median %.1fx, "
        "p99.9 %.1fx; tick median %.1fx, p99.9 %.1fx; "
        "best-of-%d query: median %.1fx, p99.9 %.1fx.\n",
        v.name, percentile(base.cpu_query_us, 50) / percentile(t.cpu_query_us, 50),
        percentile(base.cpu_query_us, 99.9) / percentile(t.cpu_query_us, 99.9),
        percentile(base.warm_cpu_us, 50) / percentile(t.warm_cpu_us, 50),
        percentile(base.warm_cpu_us, 99.9) / percentile(t.warm_cpu_us, 99.9),
        percentile(base.tick_us, 50) / percentile(t.tick_us, 50),
        percentile(base.tick_us, 99.9) / percentile(t.tick_us, 99.9), kRepeats,
        percentile(base.best_query_us, 50) / percentile(t.best_query_us, 50),
        percentile(base.best_query_us, 99.9) / percentile(t.best_query_us, 99.9));
  }
  std::printf("\n### AIST, exact narrow phase%s\n",
              options.reference_driven ? "" : " (its contacts drive the FEM)");
  metrics.print();
  node_metrics.print();
  std::printf("\n### AIST, grid narrow phase\n");
  grid_metrics.print();
  grid_node_metrics.print();
}

}  // namespace fahr::aist_bench
