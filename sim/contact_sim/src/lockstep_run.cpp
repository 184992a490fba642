// The in-process lockstep loop of the haptic response and one FEM body.
#include "fahr/contact/sim/lockstep_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>

namespace fahr::contact::sim {

LockstepRun::LockstepRun(const LockstepConfig& config, FemDriver& fem,
                         const Eigen::Vector3d& device_start_m)
    : config_(config),
      fem_(fem),
      response_([&] {
        ResponseSettings s = config.response;
        if (config.method == Method::kNaive) s.mode = ResponseMode::kNaive;
        return s;
      }()),
      penalty_(config.penalty),
      previous_device_m_(device_start_m) {
  response_.reset(device_start_m, Eigen::Quaterniond::Identity());
  rows_.reserve(fem.links().size() + config.obstacles.size());
  pending_.contacts.reserve(config.response.max_contacts);
  applied_.contacts.reserve(config.response.max_contacts);
  const std::size_t dofs = fem.positions_m().size();
  pending_forces_.assign(dofs, 0.0);
  applied_forces_.assign(dofs, 0.0);
}

void LockstepRun::haptic_tick(const Eigen::Vector3d& device_m, TickRecord& record) {
  DeviceSample device;
  device.pose_seq = tick_ + 1;
  device.position_m = device_m;
  device.velocity_mps = (device_m - previous_device_m_) / config_.dt_s;
  device.renderable_force_n = config_.renderable_force_n;
  device.max_stiffness_npm = config_.max_stiffness_npm;
  device.dt_s = config_.dt_s;
  previous_device_m_ = device_m;

  // The compliance solve reads the free-motion centres; the naive loop and
  // the penalty baseline read the published (projected) positions.
  const bool free = config_.method == Method::kForceAware;
  const SphereView spheres{free ? fem_.free_centres() : fem_.centres(), fem_.radii(),
                           fem_.compliance_index()};
  const ForceOutput* out = nullptr;
  std::fill(pending_forces_.begin(), pending_forces_.end(), 0.0);
  pending_.contacts.clear();
  pending_.state_step = fem_.step_index();
  if (config_.method == Method::kPenalty) {
    collect_rows(config_.tool, device_m, spheres, config_.obstacles, rows_);
    out = &penalty_.tick(device, rows_, fem_.step_index());
    spread_sphere_forces(penalty_.sphere_forces(), fem_.links(), pending_forces_);
    for (const ContactRow& row : rows_)
      record.max_row_penetration_m = std::max(record.max_row_penetration_m, row.penetration_m());
  } else {
    collect_rows(config_.tool, response_.proxy().position_m, spheres, config_.obstacles, rows_);
    TickInput input;
    input.device = device;
    input.rows = rows_;
    input.compliance =
        TissueCompliance{fem_.step_index(), fem_.compliance_spheres(), fem_.compliance(), {}};
    const auto start = std::chrono::steady_clock::now();
    out = &response_.tick(input);
    record.tick_time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    record.response = response_.report();
    const auto contacts = response_.contacts();
    pending_.contacts.assign(contacts.begin(), contacts.end());
  }
  record.device_m = device_m;
  record.proxy_m = out->proxy_position_m;
  record.force_n = out->force_n;
  record.tissue_reaction_n = out->tissue_reaction_n;
  record.lost_track = out->lost_track;
  record.gap_m = out->device_minus_proxy_m;
  record.active = out->active_contacts;
  record.finite = out->force_n.allFinite() && out->proxy_position_m.allFinite();
}

void LockstepRun::fem_step(TickRecord& record) {
  const bool penalty = config_.method == Method::kPenalty;
  record.fem =
      fem_.step(penalty ? nullptr : &applied_,
                penalty ? std::span<const double>(applied_forces_) : std::span<const double>());
  record.fem_stepped = true;
  const auto centres = fem_.centres();
  for (const fem::Contact& c : applied_.contacts) {
    if (c.state != fem::ContactState::kActive) continue;
    const double depth =
        fem_.radii()[c.sphere_id] - (centres[c.sphere_id] - c.plane_point_m).dot(c.normal);
    double& worst = c.kind == fem::ContactKind::kForceOnly ? record.force_only_penetration_m
                                                           : record.active_penetration_m;
    worst = std::max(worst, depth);
  }
}

void LockstepRun::run(std::uint64_t ticks,
                      const std::function<Eigen::Vector3d(std::uint64_t)>& device,
                      const std::function<void(const TickRecord&)>& observe) {
  const auto period = static_cast<std::uint64_t>(std::max(config_.fem_period_ticks, 1));
  for (std::uint64_t n = 0; n < ticks; ++n, ++tick_) {
    TickRecord record;
    record.tick = tick_;
    record.time_s = static_cast<double>(tick_) * config_.dt_s;
    // The FEM step at k reads haptic tick k - 1's output: move it aside
    // before tick k writes its own. The haptic tick at k reads the FEM's
    // newest step strictly before k, so it runs before the FEM step of k.
    const bool fem_due = tick_ % period == 0;
    if (fem_due) {
      std::swap(applied_, pending_);
      std::swap(applied_forces_, pending_forces_);
    }
    haptic_tick(device(tick_), record);
    if (fem_due) fem_step(record);
    if (observe) observe(record);
  }
}

double line_amplitude(std::span<const double> x, double dt_s, double frequency_hz) {
  // Whole periods only, so a constant or the line of another harmonic leaks nothing.
  const auto per_period = static_cast<std::size_t>(std::llround(1.0 / (frequency_hz * dt_s)));
  const std::size_t n = per_period == 0 ? 0 : x.size() / per_period * per_period;
  if (n < 2) return 0.0;
  double mean_t = 0.0, mean_x = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    mean_t += static_cast<double>(i);
    mean_x += x[i];
  }
  mean_t /= static_cast<double>(n);
  mean_x /= static_cast<double>(n);
  double stt = 0.0, stx = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) - mean_t;
    stt += t * t;
    stx += t * (x[i] - mean_x);
  }
  const double slope = stx / stt;
  double re = 0.0, im = 0.0;
  const double omega = 2.0 * std::numbers::pi * frequency_hz * dt_s;
  for (std::size_t i = 0; i < n; ++i) {
    const double detrended = x[i] - mean_x - slope * (static_cast<double>(i) - mean_t);
    re += detrended * std::cos(omega * static_cast<double>(i));
    im -= detrended * std::sin(omega * static_cast<double>(i));
  }
  return 2.0 * std::hypot(re, im) / static_cast<double>(n);
}

}  // namespace fahr::contact::sim
