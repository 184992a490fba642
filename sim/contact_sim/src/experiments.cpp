// The contact experiments on the shared scenes.
#include "fahr/contact/sim/experiments.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "fahr/contact/sim/scenes.h"

namespace fahr::contact::sim {
namespace {

constexpr double kDt = 0.001;  // haptic tick, s

int period_ticks(double fem_hz) {
  return static_cast<int>(std::lround(1.0 / (fem_hz * kDt)));
}

double boussinesq(double radius_m, double depth_m) {
  const fem::Material m = fem::neonatal_tongue();
  return 2.0 * radius_m * m.youngs_modulus_pa * depth_m / (1.0 - m.poisson_ratio * m.poisson_ratio);
}

// The FEM alone with the punch nodes prescribed at `depth_m` (fixed nodes
// moved there): its own static force, the sum of the elastic reactions.
// A long step relaxes 91 % of the remaining error per step (h / (beta + h)
// with beta = 0.01 s): 40 steps are static to 1e-40.
constexpr double kStaticStep = 0.1;

double fem_static_force(double punch_radius_m, double depth_m) {
  std::string error;
  PunchScene scene = make_punch_scene(punch_radius_m, kStaticStep, error);
  if (!scene.fem) return 0.0;
  std::vector<std::uint32_t> fixed = scene.block.fixed_nodes;
  fixed.insert(fixed.end(), scene.sphere_nodes.begin(), scene.sphere_nodes.end());
  fem::BodySettings settings = block_body_settings(kStaticStep);
  settings.sleep.enabled = false;
  fem::BodyOrError made =
      fem::Body::create(settings, scene.block.mesh.nodes_m, scene.block.mesh.tets, fixed);
  if (!made.body) return 0.0;
  fem::Body& body = *made.body;
  for (const std::uint32_t node : scene.sphere_nodes) {
    body.set_node_position(node, body.rest_position(node) - depth_m * Eigen::Vector3d::UnitY());
  }
  for (int step = 0; step < 40; ++step) body.step();
  std::vector<double> f(body.positions_m().size());
  body.elastic_forces(f);
  double sum = 0.0;
  for (const std::uint32_t node : scene.sphere_nodes) sum += f[3 * std::size_t{node} + 1];
  return sum;
}

}  // namespace

double fem_static_stiffness(double punch_radius_m) {
  constexpr double kDepth = 0.001;  // m
  return fem_static_force(punch_radius_m, kDepth) / kDepth;
}

PunchResult run_punch_experiment(double fem_hz, double punch_radius_m, double depth_m,
                                 double fem_static_npm) {
  PunchResult result;
  result.fem_hz = fem_hz;
  result.punch_radius_m = punch_radius_m;
  std::string error;
  PunchScene scene = make_punch_scene(punch_radius_m, 1.0 / fem_hz, error);
  if (!scene.fem) {
    result.finite = false;
    return result;
  }
  result.effective_radius_m = scene.effective_radius_m;
  LockstepConfig config;
  config.method = Method::kForceAware;
  config.fem_period_ticks = period_ticks(fem_hz);
  config.dt_s = kDt;
  config.tool = ToolShape{ToolKind::kFlatPunch, punch_radius_m * (1.0 + 1e-6), 0.002};
  config.response.coupling.stiffness_npm =
      1480.0;                        // the Touch X's stiffest: the proxy stops closest
  config.renderable_force_n = 50.0;  // accuracy, not force awareness, is measured here
  const double r = scene.sphere_radius_m;
  const double start_y = r + 0.001;
  const double floor_y = r - depth_m;
  const double speed = 0.02;  // m/s
  LockstepRun run(config, *scene.fem, Eigen::Vector3d(0, start_y, 0));
  // 0.6 s of hold: the force settles to 0.1 % within ~0.3 s at every rate.
  const auto ticks = static_cast<std::uint64_t>((start_y - floor_y) / speed / kDt) + 600;
  TickRecord last;
  run.run(
      ticks,
      [&](std::uint64_t k) {
        return Eigen::Vector3d(
            0.0, std::max(floor_y, start_y - speed * kDt * static_cast<double>(k)), 0.0);
      },
      [&](const TickRecord& rec) {
        last = rec;
        result.finite = result.finite && rec.finite;
      });
  result.proxy_depth_m = r - last.proxy_m.y();
  result.haptic_force_n = last.force_n.norm();
  result.boussinesq_n = boussinesq(scene.effective_radius_m, result.proxy_depth_m);
  // Small strain: the FEM's own static force is linear in the depth.
  result.fem_static_n = fem_static_npm * result.proxy_depth_m;
  result.haptic_error = (result.haptic_force_n - result.boussinesq_n) / result.boussinesq_n;
  result.fem_error = (result.fem_static_n - result.boussinesq_n) / result.boussinesq_n;
  result.haptic_vs_fem = (result.haptic_force_n - result.fem_static_n) / result.fem_static_n;
  return result;
}

OvershootResult run_overshoot_experiment(Method method, double limit_n, double device_floor_y_m) {
  OvershootResult result;
  result.method = method;
  result.limit_n = limit_n;
  std::string error;
  const double fem_hz = 100.0;
  PunchScene scene = make_punch_scene(0.01, 1.0 / fem_hz, error, kSmallPunchMesh);
  if (!scene.fem) {
    result.finite = false;
    return result;
  }
  FemDriver& fem = *scene.fem;
  LockstepConfig config;
  config.method = method;
  config.fem_period_ticks = period_ticks(fem_hz);
  config.dt_s = kDt;
  config.tool = ToolShape{ToolKind::kFlatPunch, 0.01 * (1.0 + 1e-6), 0.002};
  config.renderable_force_n = limit_n;
  result.coupling_npm = config.response.coupling.stiffness_npm;
  const double k_c = result.coupling_npm;
  const double r = scene.sphere_radius_m;
  const double start_y = r + 0.001;
  const double down = 0.01, up = 0.02;  // m/s
  LockstepRun run(config, fem, Eigen::Vector3d(0, start_y, 0));

  enum class Phase { kDescend, kHold, kRelease } phase = Phase::kDescend;
  double device_y = start_y;
  std::uint64_t hold_until = 0, release_tick = 0;
  bool seen_1x = false, released = false;
  double commanded = 0.0;
  Eigen::Vector3d freeze_proxy = Eigen::Vector3d::Zero();
  bool was_lost = false;
  std::uint64_t reengaged_tick = 0;
  bool reengaged = false;
  Eigen::Vector3d previous_force = Eigen::Vector3d::Zero();
  const std::uint64_t total = 20000;
  run.run(
      total,
      [&](std::uint64_t k) {
        if (phase == Phase::kDescend) {
          const bool deep_enough = method == Method::kPenalty ? device_y <= device_floor_y_m
                                                              : commanded >= 3.0 * limit_n;
          if (deep_enough) {
            phase = Phase::kHold;
            hold_until = k + 5000;
            result.deepest_device_y_m = device_y;
            result.strain_at_3x = fem.max_principal_green_strain();
          } else {
            device_y -= down * kDt;
          }
        } else if (phase == Phase::kHold && k >= hold_until) {
          phase = Phase::kRelease;
          release_tick = k;
          released = true;
        }
        if (phase == Phase::kRelease) device_y = std::min(start_y, device_y + up * kDt);
        return Eigen::Vector3d(0.0, device_y, 0.0);
      },
      [&](const TickRecord& rec) {
        result.finite = result.finite && rec.finite;
        commanded = method == Method::kPenalty ? rec.force_n.norm() : k_c * rec.gap_m.norm();
        result.max_commanded_n = std::max(result.max_commanded_n, commanded);
        result.max_reaction_n = std::max(result.max_reaction_n, rec.tissue_reaction_n);
        if (!seen_1x && commanded >= limit_n) {
          seen_1x = true;
          result.strain_at_1x = fem.max_principal_green_strain();
        }
        if (rec.lost_track) {
          ++result.lost_track_ticks;
          if (!was_lost) freeze_proxy = rec.proxy_m;
          result.max_reaction_lost_n = std::max(result.max_reaction_lost_n, rec.tissue_reaction_n);
          // The published gap against the commanded force: |gap| = L/K_c +
          // (F_cmd - L)/K_c, F_cmd = K_c |x_d - p_freeze| the hand's command.
          const double f_cmd = k_c * (rec.device_m - freeze_proxy).norm();
          const double expected = limit_n / k_c + (f_cmd - limit_n) / k_c;
          result.max_gap_error_m =
              std::max(result.max_gap_error_m, std::abs(rec.gap_m.norm() - expected));
        }
        if (was_lost && !rec.lost_track) {
          reengaged = true;
          reengaged_tick = rec.tick;
        }
        was_lost = rec.lost_track;
        const double step = (rec.force_n - previous_force).norm();
        previous_force = rec.force_n;
        if (rec.tick > 0) result.max_tick_step_n = std::max(result.max_tick_step_n, step);
        if (reengaged && rec.tick >= reengaged_tick && rec.tick < reengaged_tick + 50) {
          result.max_reengage_step_n = std::max(result.max_reengage_step_n, step);
        }
        if (rec.fem_stepped) {
          result.max_inverted = std::max(result.max_inverted, rec.fem.inverted_elements);
          result.finite = result.finite && rec.fem.finite;
          const double energy = fem.body().energy().elastic_j;
          result.max_elastic_energy_j = std::max(result.max_elastic_energy_j, energy);
          result.final_elastic_energy_j = energy;
          result.max_penetration_m = std::max(
              {result.max_penetration_m, rec.active_penetration_m, rec.force_only_penetration_m});
        }
        result.max_penetration_m = std::max(result.max_penetration_m, rec.max_row_penetration_m);
        if (released && rec.tick == release_tick + 1000)
          result.displacement_1s_after_release_m = fem.max_displacement_m();
      });
  result.max_inverted = std::max(result.max_inverted, fem.inverted_now());
  return result;
}

SmoothnessResult run_smoothness_experiment(Method method) {
  SmoothnessResult result;
  result.method = method;
  std::string error;
  PunchScene scene = make_punch_scene(0.005, 0.02, error, PunchMesh{2.5, 8.0, 1.5});
  if (!scene.fem) return result;
  LockstepConfig config;
  config.method = method;
  config.fem_period_ticks = 20;
  config.dt_s = kDt;
  config.tool = ToolShape{ToolKind::kFlatPunch, 0.005 * (1.0 + 1e-6), 0.002};
  config.response.coupling.stiffness_npm = 1480.0;
  config.renderable_force_n = 50.0;
  const double r = scene.sphere_radius_m;
  const double speed = 0.005;  // m/s: steady pressing
  LockstepRun run(config, *scene.fem, Eigen::Vector3d(0, r, 0));
  std::vector<double> force, times;
  double sweeps = 0.0;
  run.run(
      1700,
      [&](std::uint64_t k) {
        return Eigen::Vector3d(0.0, r - speed * kDt * static_cast<double>(k), 0.0);
      },
      [&](const TickRecord& rec) {
        if (rec.tick < 700) return;
        force.push_back(rec.force_n.norm());
        times.push_back(1e6 * rec.tick_time_s);
        sweeps += rec.response.pgs.sweeps;
      });
  result.line_n = line_amplitude(force, kDt, 50.0);
  double sum = 0.0;
  for (const double f : force) sum += f;
  result.mean_force_n = sum / static_cast<double>(force.size());
  result.mean_sweeps = sweeps / static_cast<double>(force.size());
  std::sort(times.begin(), times.end());
  result.tick_median_us = times[times.size() / 2];
  result.tick_p99_us = times[times.size() * 99 / 100];
  return result;
}

}  // namespace fahr::contact::sim
