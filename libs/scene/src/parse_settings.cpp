// The scene-wide sections: rates, run mode, DDS, device, FEM solver, contact
// and QoS overrides.
#include <algorithm>
#include <cmath>

#include "parsers.h"

namespace fahr::scene::detail {

namespace {

// Whole multiples are checked on the nanosecond periods; 1 ns of rounding in
// 1e9 / hz is not a real mismatch.
bool is_whole_multiple(std::chrono::nanoseconds period, std::chrono::nanoseconds base) {
  const long long remainder = period.count() % base.count();
  return remainder <= 1 || base.count() - remainder <= 1;
}

std::optional<std::size_t> body_by_name(const ParseContext& ctx, const YAML::Node& node,
                                        const std::string& path, const std::vector<Body>& bodies) {
  std::string name;
  if (!read_string(ctx.log, node, path, name)) return std::nullopt;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].name == name) return i;
  }
  std::string names;
  for (const Body& body : bodies) names += (names.empty() ? "" : ", ") + body.name;
  ctx.log.add(node.Mark(), path, "no body named '" + name + "'; bodies: " + names);
  return std::nullopt;
}

DeviceLimits parse_limits(const MapReader& device_map) {
  DeviceLimits limits;
  const MapReader map(device_map.log(), device_map.value("limits"), device_map.child_path("limits"),
                      {"peak_force_n", "continuous_force_n", "max_stiffness_npm", "workspace_m"});
  double value = 0.0;
  if (map.read("peak_force_n", open_closed(0.0, 100.0), value)) limits.peak_force_n = value;
  if (map.read("continuous_force_n", open_closed(0.0, 100.0), value)) {
    limits.continuous_force_n = value;
  }
  if (map.read("max_stiffness_npm", open_closed(0.0, 1.0e5), value)) {
    limits.max_stiffness_npm = value;
  }
  Eigen::Vector3d workspace;
  if (map.read("workspace_m", open_closed(0.0, 2.0), workspace)) limits.workspace_m = workspace;
  if (limits.peak_force_n && limits.continuous_force_n &&
      *limits.continuous_force_n > *limits.peak_force_n) {
    map.log().add(map.value("continuous_force_n").Mark(), map.child_path("continuous_force_n"),
                  "the continuous force cannot exceed the peak force");
  }
  return limits;
}

void check_custom_limits(const MapReader& map, const DeviceLimits& limits) {
  const bool complete = limits.peak_force_n && limits.continuous_force_n &&
                        limits.max_stiffness_npm && limits.workspace_m;
  if (!complete) {
    map.log().add(map.key_mark("model"), map.child_path("limits"),
                  "model 'custom' needs every limit: peak_force_n, continuous_force_n, "
                  "max_stiffness_npm, workspace_m");
  }
}

// Tool: the named one, else the scene's only tool; a device needs one.
std::optional<std::size_t> device_tool(const ParseContext& ctx, const MapReader& map,
                                       const std::vector<Body>& bodies) {
  if (map.has("tool")) {
    const std::optional<std::size_t> index =
        body_by_name(ctx, map.value("tool"), map.child_path("tool"), bodies);
    if (index && bodies[*index].role != BodyRole::kTool) {
      ctx.log.add(map.value("tool").Mark(), map.child_path("tool"),
                  "body '" + bodies[*index].name + "' is a " +
                      std::string(to_string(bodies[*index].role)) + ", not a tool");
      return std::nullopt;
    }
    return index;
  }
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].role == BodyRole::kTool) return i;
  }
  ctx.log.add(map.mark(), map.path(), "a device drives a tool, but no body has role: tool");
  return std::nullopt;
}

void parse_backend_source(const ParseContext& ctx, const MapReader& map, DeviceSettings& device) {
  if (device.backend != DeviceBackend::kSimulated && map.has("script")) {
    map.reject("script", "scripts drive the simulated back-end only");
  }
  map.read_enum("script", kDeviceScriptNames, device.script);
  if (device.backend != DeviceBackend::kReplay) {
    if (map.has("replay_file")) map.reject("replay_file", "only the replay back-end reads one");
    return;
  }
  std::string file;
  if (!map.require("replay_file") || !map.read("replay_file", file)) return;
  device.replay_file = ctx.resolve(file);
  std::error_code error;
  if (ctx.options.check_files && !std::filesystem::is_regular_file(device.replay_file, error)) {
    ctx.log.add(map.value("replay_file").Mark(), map.child_path("replay_file"),
                "replay file not found: " + device.replay_file.string());
  }
}

void parse_pair_list(const ParseContext& ctx, const MapReader& map, std::string_view key,
                     const std::vector<Body>& bodies, std::vector<BodyIndexPair>& out) {
  if (!map.has(key)) return;
  const YAML::Node list = map.value(key);
  const std::string path = map.child_path(key);
  if (!list.IsSequence()) {
    ctx.log.add(list.Mark(), path,
                "expected a sequence of [body, body] pairs, got " + describe(list));
    return;
  }
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node pair = list[i];
    const std::string pair_path = path + "[" + std::to_string(i) + "]";
    if (!pair.IsSequence() || pair.size() != 2) {
      ctx.log.add(pair.Mark(), pair_path, "expected [body, body], got " + describe(pair));
      continue;
    }
    const auto a = body_by_name(ctx, pair[0], pair_path + "[0]", bodies);
    const auto b = body_by_name(ctx, pair[1], pair_path + "[1]", bodies);
    if (!a || !b) continue;
    if (*a == *b) {
      ctx.log.add(pair.Mark(), pair_path, "a body cannot be paired with itself");
      continue;
    }
    out.emplace_back(std::min(*a, *b), std::max(*a, *b));
  }
}

// Only deformable/obstacle pairs can be declared in contact: tool pairs are
// always tested, and the contact contract has no rigid/rigid or
// deformable/deformable contact.
void check_include_roles(const ParseContext& ctx, const MapReader& map,
                         const std::vector<Body>& bodies, const ContactSettings& contact) {
  for (const auto& [a, b] : contact.include_pairs) {
    const BodyRole ra = bodies[a].role;
    const BodyRole rb = bodies[b].role;
    const bool deformable_obstacle = (ra == BodyRole::kDeformable && rb == BodyRole::kObstacle) ||
                                     (ra == BodyRole::kObstacle && rb == BodyRole::kDeformable);
    if (deformable_obstacle) continue;
    std::string why = "only deformable/obstacle pairs can be declared in contact";
    if (ra == BodyRole::kTool || rb == BodyRole::kTool) why += " (tool pairs always are)";
    if (ra == rb && ra == BodyRole::kObstacle) why += " (obstacles never move)";
    if (ra == rb && ra == BodyRole::kDeformable) {
      why += " (no deformable/deformable contact in the contact contract)";
    }
    ctx.log.add(map.key_mark("include_pairs"), map.child_path("include_pairs"),
                "[" + bodies[a].name + ", " + bodies[b].name + "]: " + why);
  }
  for (const BodyIndexPair& pair : contact.include_pairs) {
    if (std::find(contact.exclude_pairs.begin(), contact.exclude_pairs.end(), pair) !=
        contact.exclude_pairs.end()) {
      ctx.log.add(map.key_mark("exclude_pairs"), map.child_path("exclude_pairs"),
                  "pair [" + bodies[pair.first].name + ", " + bodies[pair.second].name +
                      "] is both included and excluded");
    }
  }
}

}  // namespace

Rates parse_rates(const ParseContext& ctx, const MapReader& top) {
  Rates rates;
  if (!top.has("rates")) return rates;
  const MapReader map(ctx.log, top.value("rates"), "rates", {"haptic_hz", "fem_hz", "status_hz"});
  map.read("haptic_hz", open_closed(0.0, 10000.0), rates.haptic_hz);
  map.read("fem_hz", open_closed(0.0, 10000.0), rates.fem_hz);
  map.read("status_hz", open_closed(0.0, 1000.0), rates.status_hz);
  return rates;
}

RunSettings parse_run(const ParseContext& ctx, const MapReader& top, const Rates& rates) {
  RunSettings run;
  run.base_period = std::min(rates.haptic_period(), rates.fem_period());
  if (!top.has("run")) return run;
  const MapReader map(
      ctx.log, top.value("run"), "run",
      {"mode", "base_period_ms", "duration_s", "fem_state_delay_steps", "spin_wait"});
  map.read_enum("mode", kRunModeNames, run.mode);
  map.read_s("duration_s", closed(0.0, 1.0e6), run.duration);
  map.read("spin_wait", run.spin_wait);
  if (run.mode != RunMode::kLockstep) {
    for (const char* key : {"base_period_ms", "fem_state_delay_steps"}) {
      if (map.has(key)) map.reject(key, "it applies to mode: lockstep only");
    }
    return run;
  }
  map.read("fem_state_delay_steps", 0, 100, run.fem_state_delay_steps);
  map.read_ms("base_period_ms", open_closed(0.0, 1000.0), run.base_period);
  if (run.base_period.count() <= 0) return run;
  const struct {
    const char* key;
    std::chrono::nanoseconds period;
  } periods[] = {{"rates.haptic_hz", rates.haptic_period()}, {"rates.fem_hz", rates.fem_period()}};
  for (const auto& [key, period] : periods) {
    if (!is_whole_multiple(period, run.base_period) || period < run.base_period) {
      ctx.log.add(
          map.key_mark(map.has("base_period_ms") ? "base_period_ms" : "mode"), "run.base_period_ms",
          std::string("in lockstep the period of ") + key + " (" + std::to_string(period.count()) +
              " ns) must be a whole multiple of the base period (" +
              std::to_string(run.base_period.count()) + " ns)");
    }
  }
  return run;
}

DdsSettings parse_dds(const ParseContext& ctx, const MapReader& top) {
  DdsSettings dds;
  if (!top.has("dds")) return dds;
  const MapReader map(ctx.log, top.value("dds"), "dds", {"vendor", "domain_id"});
  map.read_enum("vendor", kDdsVendorNames, dds.vendor);
  map.read("domain_id", 0, kMaxDomainId, dds.domain_id);
  return dds;
}

std::optional<DeviceSettings> parse_device(const ParseContext& ctx, const MapReader& top,
                                           const std::vector<Body>& bodies) {
  if (!top.has("device")) return std::nullopt;
  const MapReader map(ctx.log, top.value("device"), "device",
                      {"backend", "model", "limits", "tool", "script", "replay_file",
                       "world_from_device", "motion_scale"});
  if (!map.is_map()) return std::nullopt;
  DeviceSettings device;
  map.read_enum("backend", kDeviceBackendNames, device.backend);
  map.read_enum("model", kDeviceModelNames, device.model);
  if (map.has("limits")) device.limits = parse_limits(map);
  if (device.model == DeviceModel::kCustom) check_custom_limits(map, device.limits);
  if (const std::optional<std::size_t> tool = device_tool(ctx, map, bodies)) {
    device.tool_body = *tool;
  }
  parse_backend_source(ctx, map, device);
  if (map.has("world_from_device")) {
    device.world_from_device =
        parse_pose(ctx, map.value("world_from_device"), map.child_path("world_from_device"));
  }
  map.read("motion_scale", open_closed(0.0, 100.0), device.motion_scale);
  return device;
}

FemSolverSettings parse_solver(const ParseContext& ctx, const MapReader& top) {
  FemSolverSettings s;
  if (!top.has("solver")) return s;
  const MapReader map(
      ctx.log, top.value("solver"), "solver",
      {"linear_solver", "cg_tolerance", "cg_max_iterations", "projection_max_iterations",
       "projection_tolerance_m", "compliance", "compliance_columns", "max_candidate_contacts",
       "max_contact_age_ms", "sleep_speed_mps", "volume_floor_ratio", "factor_latency_ms"});
  map.read_enum("linear_solver", kLinearSolverNames, s.linear_solver);
  if (s.linear_solver != LinearSolver::kPcg) {
    for (const char* key : {"cg_tolerance", "cg_max_iterations"}) {
      if (map.has(key)) map.reject(key, "it applies to linear_solver: pcg only");
    }
  }
  map.read("cg_tolerance", open(0.0, 1.0), s.cg_tolerance);
  map.read("cg_max_iterations", 1, 100000, s.cg_max_iterations);
  map.read("projection_max_iterations", 1, 10000, s.projection_max_iterations);
  map.read("projection_tolerance_m", open_closed(0.0, 1.0e-2), s.projection_tolerance_m);
  map.read_enum("compliance", kComplianceModeNames, s.compliance);
  map.read_enum("compliance_columns", kComplianceColumnsNames, s.compliance_columns);
  // The compliance block is n^2 floats per DeformationState: 1024 is 4 MiB.
  map.read("max_candidate_contacts", 0, 1024, s.max_candidate_contacts);
  map.read_ms("max_contact_age_ms", open_closed(0.0, 10000.0), s.max_contact_age);
  map.read("sleep_speed_mps", closed(0.0, 1.0), s.sleep_speed_mps);
  map.read("volume_floor_ratio", closed(0.0, 0.9), s.volume_floor_ratio);
  map.read_ms("factor_latency_ms", closed(0.0, 1000.0), s.factor_latency);
  return s;
}

ContactSettings parse_contact(const ParseContext& ctx, const MapReader& top,
                              const std::vector<Body>& bodies) {
  ContactSettings c;
  if (!top.has("contact")) return c;
  const MapReader map(
      ctx.log, top.value("contact"), "contact",
      {"response", "coupling_stiffness_npm", "coupling_damping_nspm", "force_aware_hysteresis",
       "held_proxy", "penalty_stiffness_npm", "deformable_obstacle_margin_m", "include_pairs",
       "exclude_pairs", "tool_stops_at_anatomy"});
  map.read_enum("response", kContactResponseNames, c.response);
  map.read("coupling_stiffness_npm", open_closed(0.0, 1.0e5), c.coupling_stiffness_npm);
  map.read("coupling_damping_nspm", closed(0.0, 1.0e3), c.coupling_damping_nspm);
  map.read("force_aware_hysteresis", closed(0.0, 0.9), c.force_aware_hysteresis);
  map.read_enum("held_proxy", kHeldProxyNames, c.held_proxy);
  map.read("penalty_stiffness_npm", open_closed(0.0, 1.0e6), c.penalty_stiffness_npm);
  map.read("deformable_obstacle_margin_m", closed(0.0, 1.0), c.deformable_obstacle_margin_m);
  parse_pair_list(ctx, map, "include_pairs", bodies, c.include_pairs);
  parse_pair_list(ctx, map, "exclude_pairs", bodies, c.exclude_pairs);
  map.read("tool_stops_at_anatomy", c.tool_stops_at_anatomy);
  check_include_roles(ctx, map, bodies, c);
  return c;
}

std::optional<GlotticViewSettings> parse_glottic_view(const ParseContext& ctx, const MapReader& top,
                                                      const std::vector<Body>& bodies) {
  if (!top.has("glottic_view")) return std::nullopt;
  const MapReader map(ctx.log, top.value("glottic_view"), "glottic_view",
                      {"opening_centre_m", "opening_normal", "opening_radius_m",
                       "opening_major_axis", "opening_minor_radius_m", "eye_in_tool_m", "rate_hz"});
  GlotticViewSettings g;
  for (const std::string_view key :
       {"opening_centre_m", "opening_normal", "opening_radius_m", "eye_in_tool_m"}) {
    map.require(key);
  }
  map.read("opening_centre_m", closed(-1000.0, 1000.0), g.opening_centre_m);
  if (map.read("opening_normal", closed(-1.0, 1.0), g.opening_normal)) {
    if (std::abs(g.opening_normal.norm() - 1.0) > 1e-3) {
      ctx.log.add(map.value("opening_normal").Mark(), map.child_path("opening_normal"),
                  "the normal must have unit length (within 1e-3)");
    }
    g.opening_normal.normalize();
  }
  map.read("opening_radius_m", open_closed(0.0, 0.1), g.opening_radius_m);
  const bool has_axis = map.read("opening_major_axis", closed(-1.0, 1.0), g.opening_major_axis);
  const bool has_minor =
      map.read("opening_minor_radius_m", open_closed(0.0, 0.1), g.opening_minor_radius_m);
  if (has_minor != has_axis) {
    const std::string_view given = has_minor ? "opening_minor_radius_m" : "opening_major_axis";
    ctx.log.add(map.value(given).Mark(), map.child_path(given),
                "an elliptic opening needs both opening_major_axis and opening_minor_radius_m");
  } else if (has_minor) {
    const Eigen::Vector3d in_plane =
        g.opening_major_axis - g.opening_major_axis.dot(g.opening_normal) * g.opening_normal;
    if (std::abs(g.opening_major_axis.norm() - 1.0) > 1e-3 ||
        in_plane.norm() < 0.999 * g.opening_major_axis.norm()) {
      ctx.log.add(map.value("opening_major_axis").Mark(), map.child_path("opening_major_axis"),
                  "the major axis must have unit length and lie in the opening's plane "
                  "(perpendicular to opening_normal)");
    }
    if (g.opening_minor_radius_m > g.opening_radius_m) {
      ctx.log.add(map.value("opening_minor_radius_m").Mark(),
                  map.child_path("opening_minor_radius_m"),
                  "the minor radius must not exceed opening_radius_m");
    }
  }
  map.read("eye_in_tool_m", closed(-10.0, 10.0), g.eye_in_tool_m);
  map.read("rate_hz", open_closed(0.0, 100.0), g.rate_hz);
  const bool has_tool = std::any_of(bodies.begin(), bodies.end(),
                                    [](const Body& b) { return b.role == BodyRole::kTool; });
  if (!has_tool) {
    ctx.log.add(map.mark(), "glottic_view", "the eye rides on the tool: the scene has no tool");
  }
  return g;
}

std::map<std::string, QosOverride, std::less<>> parse_qos(const ParseContext& ctx,
                                                          const MapReader& top) {
  std::map<std::string, QosOverride, std::less<>> qos;
  if (!top.has("qos")) return qos;
  const MapReader topics(
      ctx.log, top.value("qos"), "qos",
      {kTopicNames[0], kTopicNames[1], kTopicNames[2], kTopicNames[3], kTopicNames[4],
       kTopicNames[5], kTopicNames[6], kTopicNames[7], kTopicNames[8]});
  for (const std::string_view topic : kTopicNames) {
    if (!topics.has(topic)) continue;
    const MapReader map(ctx.log, topics.value(topic), topics.child_path(topic),
                        {"deadline_ms", "history_depth", "reliability"});
    QosOverride entry;
    std::chrono::nanoseconds deadline{0};
    if (map.read_ms("deadline_ms", open_closed(0.0, 10000.0), deadline)) entry.deadline = deadline;
    int depth = 1;
    if (map.read("history_depth", 1, 100000, depth)) entry.history_depth = depth;
    Reliability reliability = Reliability::kReliable;
    if (map.read_enum("reliability", kReliabilityNames, reliability)) {
      entry.reliability = reliability;
    }
    qos.emplace(std::string(topic), entry);
  }
  return qos;
}

}  // namespace fahr::scene::detail
