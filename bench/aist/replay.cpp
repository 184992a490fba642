// Query timing on recorded states: `aist_bench record FILE` runs the closed
// loop of the trajectory section once (the FEM driven by the AIST's exact
// contacts) and writes every blade pose and FEM state; `aist_bench replay
// FILE` replays them into the AIST query alone. Two binaries (before and after
// a change to the query) then time the same states and print a hash of the
// contacts each reported, so a change that claims identical contacts can be
// checked bit for bit; a replay takes seconds where the trajectory takes
// minutes (FEM, baseline, metrics).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fstream>
#include <numeric>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "fahr/collision/deepest_contacts.h"
#include "fahr/collision/field_grid.h"
#include "fahr/collision/sphere_query.h"
#include "fahr/collision/sphere_tree.h"
#include "fahr/layout_links/fem_links.h"
#include "fahr/sphere_layout/fill_spheres.h"
#include "sections.h"
#include "sphere_contact_set.h"
#include "stats.h"

namespace fahr::aist_bench {
namespace {

constexpr std::uint64_t kMagic = 0x31594150455241ULL;  // "ARPEAY1": the file's format, version 1

struct Recording {
  std::uint64_t nodes = 0;
  std::vector<Eigen::Matrix4d> poses;       // world_from_body of the blade, per tick
  std::vector<std::int64_t> state_of_tick;  // index into states, or -1: the previous state stands
  std::vector<std::vector<double>> states;  // FEM positions, m, 3 per node
};

template <typename T>
void write_pod(std::ofstream& out, const T& value) {
  out.write(reinterpret_cast<const char*>(&value), sizeof(T));
}

template <typename T>
void read_pod(std::ifstream& in, T& value) {
  in.read(reinterpret_cast<char*>(&value), sizeof(T));
  if (!in) throw std::runtime_error("replay: the recording ends early");
}

Recording load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("replay: cannot open " + path);
  std::uint64_t magic = 0, ticks = 0;
  read_pod(in, magic);
  if (magic != kMagic)
    throw std::runtime_error("replay: " + path + " is not an aist_bench recording");
  Recording r;
  read_pod(in, r.nodes);
  read_pod(in, ticks);
  if (ticks == 0 || ticks > 10'000'000 || r.nodes == 0 || r.nodes > 100'000'000) {
    throw std::runtime_error("replay: implausible header in " + path);
  }
  for (std::uint64_t t = 0; t < ticks; ++t) {
    Eigen::Matrix4d pose;
    read_pod(in, pose);
    std::uint8_t fresh = 0;
    read_pod(in, fresh);
    r.poses.push_back(pose);
    if (fresh != 0) {
      std::vector<double> x(3 * r.nodes);
      in.read(reinterpret_cast<char*>(x.data()),
              static_cast<std::streamsize>(x.size() * sizeof(double)));
      if (!in) throw std::runtime_error("replay: the recording ends early");
      r.states.push_back(std::move(x));
      r.state_of_tick.push_back(static_cast<std::int64_t>(r.states.size()) - 1);
    } else {
      if (r.states.empty()) throw std::runtime_error("replay: the first tick carries no state");
      r.state_of_tick.push_back(-1);
    }
  }
  return r;
}

// FNV-1a over the bytes of every field a contact reports, in buffer order.
struct ContactHash {
  std::uint64_t value = 1469598103934665603ULL;
  void bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) value = (value ^ p[i]) * 1099511628211ULL;
  }
  void add(const collision::SphereContact& c) {
    bytes(&c.sphere_id, sizeof(c.sphere_id));
    bytes(c.point_m.data(), 3 * sizeof(double));
    bytes(c.normal.data(), 3 * sizeof(double));
    bytes(&c.depth_m, sizeof(double));
    const std::uint8_t flags = static_cast<std::uint8_t>(
        (c.candidate ? 1 : 0) | (c.normal_without_history ? 2 : 0) | (c.has_surface ? 4 : 0));
    bytes(&flags, 1);
    if (c.has_surface) {
      bytes(c.surface_point_m.data(), 3 * sizeof(double));
      bytes(&c.surface_depth_m, sizeof(double));
    }
  }
};

// Rows the haptic tick keeps of a query's contacts (its tissue_row_budget:
// msg::MAX_COMPLIANCE_SPHERES, the response's row count).
constexpr std::size_t kServiceRows = 64;

struct ReplayVariant {
  const char* name;
  collision::QuerySettings settings;
  // > 0: the timed work is the haptic tick's, the query and then the `keep`
  // deepest selected (and completed, defer_outside_contacts); row_hash hashes them.
  std::size_t keep;
  collision::PrePenetrationMemory memory;
  collision::ContactBuffer buffer;
  std::vector<std::uint32_t> rows;
  std::vector<double> first_us, warm_us;
  ContactHash hash;      // every contact in buffer order
  ContactHash set_hash;  // per query the sum of each contact's hash: the same contacts in any order
  ContactHash row_hash;  // the kept rows, in row order
  double tested_sum = 0.0, contacts_sum = 0.0, nodes_sum = 0.0, inside_sum = 0.0;
  std::uint32_t tested_max = 0, contacts_max = 0, inside_max = 0;
};

// The haptic tick's row selection (services/haptic/src/haptic_loop.cpp)
// for a variant that keeps rows; returns how many.
std::size_t select_rows(const collision::SphereTree& tree, const collision::RigidBody& blade,
                        ReplayVariant& v) {
  if (v.keep == 0) return 0;
  const std::size_t kept = collision::select_deepest(v.buffer, v.keep, v.rows);
  collision::complete_deferred(tree, blade, v.settings, v.buffer, v.rows.data(), kept);
  return kept;
}

}  // namespace

void record_states(const Scene& scene, const Options& options, const std::string& path) {
  const sphere_layout::SphereLayout layout =
      sphere_layout::fill_spheres(scene.tongue, trajectory_fill(options));
  const fem::SphereLinks links = layout_links::to_fem_links(layout, options.skin_m);
  auto body = make_tongue_body(scene);
  collision::SphereState state(layout);
  collision::SphereTree tree(layout);
  const collision::FieldGrid grid(scene.blade_sdf);
  collision::QuerySettings settings = trajectory_query(options);
  collision::PrePenetrationMemory memory(layout.size());
  collision::ContactBuffer buffer(4096);
  collision::RigidBody blade{1, &scene.blade_sdf, Eigen::Isometry3d::Identity(), &grid};
  fem::ContactSet set;
  set.contacts.reserve(4096);
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("record: cannot write " + path);
  const std::uint64_t nodes = body->positions_m().size() / 3;
  write_pod(out, kMagic);
  write_pod(out, nodes);
  write_pod(out, static_cast<std::uint64_t>(options.ticks));
  for (int tick = 0; tick < options.ticks; ++tick) {
    const double s = static_cast<double>(tick) / (options.ticks - 1);
    blade.world_from_body = blade_pose(scene, s, options.lever_depth_m);
    const bool fresh = tick % options.fem_every == 0;
    if (fresh) {
      fill_sphere_contacts(buffer, body->step_index(), set);
      body->step(&set, &links);
      state.update(layout, body->positions_m());
      tree.refit(state);
    }
    buffer.clear();
    collision::query_spheres(tree, state, blade, settings, memory, buffer);
    const Eigen::Matrix4d pose = blade.world_from_body.matrix();
    write_pod(out, pose);
    write_pod(out, static_cast<std::uint8_t>(fresh ? 1 : 0));
    if (fresh) {
      const auto x = body->positions_m();
      out.write(reinterpret_cast<const char*>(x.data()),
                static_cast<std::streamsize>(x.size() * sizeof(double)));
    }
  }
  if (!out) throw std::runtime_error("record: writing " + path + " failed");
  std::printf("Recorded %d ticks (FEM every %d, %llu nodes) to %s.\n", options.ticks,
              options.fem_every, static_cast<unsigned long long>(nodes), path.c_str());
}

void replay_states(const Scene& scene, const Options& options, const std::string& path) {
  const Recording rec = load(path);
  const sphere_layout::SphereLayout layout =
      sphere_layout::fill_spheres(scene.tongue, trajectory_fill(options));
  collision::SphereState state(layout);
  collision::SphereTree tree(layout);
  const collision::FieldGrid grid(scene.blade_sdf);
  if (rec.states.front().size() != 3 * static_cast<std::size_t>(scene.tongue.node_count())) {
    throw std::runtime_error("replay: the recording is of another tongue mesh");
  }
  collision::QuerySettings bench;  // the trajectory section's
  bench.contact_skin_m = options.skin_m;
  bench.candidate_margin_m = kCandidateMarginM;
  bench.approach_margin_m = options.approach_margin_m;
  bench.surface_probe = options.surface_probe;
  collision::QuerySettings bench_grid = bench;
  bench_grid.exact_narrow_phase = false;
  // As services/haptic/src/haptic_loop.cpp sets it: grid narrow phase, 1 mm candidates.
  collision::QuerySettings service = bench_grid;
  service.candidate_margin_m = 1e-3;
  collision::QuerySettings service_plain = service;
  service_plain.surface_probe = collision::QuerySettings::SurfaceProbe::kNone;
  collision::QuerySettings service_deepest = service;
  service_deepest.deepest_only = 64;
  collision::QuerySettings service_deferred = service_plain;
  service_deferred.defer_outside_contacts = true;
  std::deque<ReplayVariant> variants;
  int added = 0;
  auto add = [&](const char* name, const collision::QuerySettings& s, std::size_t keep) {
    const int index = added++;
    if (options.replay_only >= 0 && index != options.replay_only) return;
    variants.push_back({name,
                        s,
                        keep,
                        collision::PrePenetrationMemory(layout.size()),
                        collision::ContactBuffer(4096),
                        std::vector<std::uint32_t>(4096),
                        {},
                        {},
                        {},
                        {},
                        {}});
  };
  add("grid narrow phase (trajectory's settings)", bench_grid, 0);
  add("exact narrow phase (trajectory's settings)", bench, 0);
  add("grid, 1 mm candidates (the service's settings)", service, 0);
  add("grid, 1 mm candidates, deepest_only 64", service_deepest, 0);
  add("grid, 1 mm candidates, no surface probe", service_plain, 0);
  add("the same, then the 64 deepest kept (the service's tick before)", service_plain,
      kServiceRows);
  add("the same, outside contacts deferred, the 64 deepest completed (the service's tick now)",
      service_deferred, kServiceRows);
  if (variants.empty()) throw std::runtime_error("replay: --replay-only names no variant");
  // Evicting the core's L2 (2 MB here) between queries stands for the rest
  // of a haptic tick (and other processes) running in between.
  std::vector<std::uint64_t> evict(options.evict_bytes / sizeof(std::uint64_t), 1);
  std::vector<std::size_t> order(variants.size());
  std::iota(order.begin(), order.end(), 0);
  std::mt19937 shuffler(7);
  std::vector<double> refit_us;
  collision::RigidBody blade{1, &scene.blade_sdf, Eigen::Isometry3d::Identity(), &grid};
  std::uint64_t sink = 0;
  const std::size_t ticks = rec.poses.size();
  for (auto& v : variants) {
    v.first_us.assign(ticks, 1e300);
    v.warm_us.assign(ticks, 1e300);
  }
  // Each pass replays every tick from a fresh memory; a tick's time is its
  // least over the passes, which drops the preemptions and cache pollution of
  // other processes on a shared machine (one pass: what one run sees).
  for (int pass = 0; pass < options.replay_passes; ++pass) {
    for (auto& v : variants) v.memory = collision::PrePenetrationMemory(layout.size());
    for (std::size_t tick = 0; tick < ticks; ++tick) {
      blade.world_from_body.matrix() = rec.poses[tick];
      if (rec.state_of_tick[tick] >= 0) {
        const double start = thread_cpu_us();
        state.update(layout, rec.states[static_cast<std::size_t>(rec.state_of_tick[tick])]);
        tree.refit(state);
        refit_us.push_back(thread_cpu_us() - start);
      }
      std::shuffle(order.begin(), order.end(), shuffler);
      for (const std::size_t who : order) {
        ReplayVariant& v = variants[who];
        for (auto& e : evict) sink += (e += 1);
        v.buffer.clear();
        const double start = thread_cpu_us();
        const collision::QueryStats stats =
            collision::query_spheres(tree, state, blade, v.settings, v.memory, v.buffer);
        const std::size_t kept = select_rows(tree, blade, v);
        v.first_us[tick] = std::min(v.first_us[tick], thread_cpu_us() - start);
        if (pass == 0) {
          std::uint64_t sum = 0;
          for (const auto& c : v.buffer) {
            v.hash.add(c);
            ContactHash one;
            one.add(c);
            sum += one.value;
          }
          v.set_hash.bytes(&sum, sizeof(sum));
          for (std::size_t r = 0; r < kept; ++r) v.row_hash.add(v.buffer[v.rows[r]]);
          v.tested_sum += stats.spheres_tested;
          v.nodes_sum += stats.nodes_visited;
          v.contacts_sum += stats.contacts;
          v.tested_max = std::max(v.tested_max, stats.spheres_tested);
          v.contacts_max = std::max(v.contacts_max, stats.contacts);
          v.inside_sum += stats.spheres_inside;
          v.inside_max = std::max(v.inside_max, stats.spheres_inside);
        }
        v.buffer.clear();
        const double warm_start = thread_cpu_us();
        collision::query_spheres(tree, state, blade, v.settings, v.memory, v.buffer);
        select_rows(tree, blade, v);
        v.warm_us[tick] = std::min(v.warm_us[tick], thread_cpu_us() - warm_start);
      }
    }
  }
  const double n = static_cast<double>(rec.poses.size());
  std::printf(
      "\n## Replay of %s: %zu ticks, %zu FEM states, %zu spheres, %zu kB written before each first "
      "run (evicts L2), per tick the least of %d passes (checksum %llu)\n\n",
      path.c_str(), rec.poses.size(), rec.states.size(), layout.size(), options.evict_bytes / 1024,
      options.replay_passes, static_cast<unsigned long long>(sink % 10));
  std::printf(
      "| query | first run thread CPU: median / p99 / p99.9 / max (us) | warm rerun: median / p99 "
      "/ p99.9 / max (us) | nodes visited (mean) | spheres tested: mean / max | contacts: mean / "
      "max | centre inside: mean / max | contact hash: in order / as sets | row hash |\n");
  std::printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  for (const auto& v : variants) {
    char rows[32] = "";
    if (v.keep > 0)
      std::snprintf(rows, sizeof(rows), "%016llx",
                    static_cast<unsigned long long>(v.row_hash.value));
    std::printf(
        "| %s | %.1f / %.1f / %.1f / %.1f | %.1f / %.1f / %.1f / %.1f | %.0f | %.0f / %u | %.0f / "
        "%u | %.0f / %u | %016llx / %016llx | %s |\n",
        v.name, percentile(v.first_us, 50), percentile(v.first_us, 99),
        percentile(v.first_us, 99.9), percentile(v.first_us, 100), percentile(v.warm_us, 50),
        percentile(v.warm_us, 99), percentile(v.warm_us, 99.9), percentile(v.warm_us, 100),
        v.nodes_sum / n, v.tested_sum / n, v.tested_max, v.contacts_sum / n, v.contacts_max,
        v.inside_sum / n, v.inside_max, static_cast<unsigned long long>(v.hash.value),
        static_cast<unsigned long long>(v.set_hash.value), rows);
  }
  std::printf("\nupdate+refit thread CPU: median %.1f us, p99.9 %.1f us.\n",
              percentile(refit_us, 50), percentile(refit_us, 99.9));
}

}  // namespace fahr::aist_bench
