// Gateway metrics from servo-loop snapshots.
#include "fahr/gateway_service/status_reporter.h"

#include <cstdio>

namespace fahr::gateway_service {
namespace {
double ms(std::chrono::nanoseconds d) {
  return static_cast<double>(d.count()) * 1e-6;
}
}  // namespace

void GatewayMetrics::take_newest() {
  if (!latest_.fetch()) return;
  last_ = latest_.value();
  if (last_.motion_to_force.count() > 0) last_latency_ = last_.motion_to_force;
}

void GatewayMetrics::fill(std::vector<std::pair<std::string, double>>& metrics) {
  std::lock_guard lock(last_mutex_);
  take_newest();
  const StatusSnapshot& s = last_;
  const device::LatencyHistogram& latency = last_latency_;
  metrics.emplace_back("motion_to_force_count", static_cast<double>(latency.count()));
  metrics.emplace_back("motion_to_force_p50_ms", ms(latency.percentile(0.5)));
  metrics.emplace_back("motion_to_force_p99_ms", ms(latency.percentile(0.99)));
  metrics.emplace_back("motion_to_force_p999_ms", ms(latency.percentile(0.999)));
  metrics.emplace_back("motion_to_force_max_ms", ms(latency.max()));
  const device::LatencyHistogram& run = s.motion_to_force_run;
  metrics.emplace_back("motion_to_force_run_count", static_cast<double>(run.count()));
  metrics.emplace_back("motion_to_force_run_p50_ms", ms(run.percentile(0.5)));
  metrics.emplace_back("motion_to_force_run_p99_ms", ms(run.percentile(0.99)));
  metrics.emplace_back("motion_to_force_run_max_ms", ms(run.max()));
  metrics.emplace_back("safety_state", static_cast<double>(s.safety_state));
  metrics.emplace_back("renderable_force_n", s.renderable_force_n);
  metrics.emplace_back("peak_force_n", s.peak_force_n);
  metrics.emplace_back("thermal_heat", s.heat);
  metrics.emplace_back("energy_to_hand_mj", s.energy_to_hand_j * 1e3);
  metrics.emplace_back("passivity_dissipated_mj", s.passivity_dissipated_j * 1e3);
  metrics.emplace_back("passivity_active_ticks", static_cast<double>(s.passivity_active_ticks));
  metrics.emplace_back("commands_accepted", static_cast<double>(s.safety.accepted));
  metrics.emplace_back("rejected_non_finite", static_cast<double>(s.safety.rejected_non_finite));
  metrics.emplace_back("rejected_stale", static_cast<double>(s.safety.rejected_stale));
  metrics.emplace_back("rejected_from_future", static_cast<double>(s.safety.rejected_from_future));
  metrics.emplace_back("rejected_out_of_order",
                       static_cast<double>(s.safety.rejected_out_of_order));
  metrics.emplace_back("saturated_ticks", static_cast<double>(s.safety.saturated_ticks));
  metrics.emplace_back("rate_limited_ticks", static_cast<double>(s.safety.rate_limited_ticks));
  metrics.emplace_back("silence_events", static_cast<double>(s.safety.silence_events));
  metrics.emplace_back("resumed_events", static_cast<double>(s.safety.resumed_events));
  metrics.emplace_back("catch_up_ticks", static_cast<double>(s.safety.catch_up_ticks));
  metrics.emplace_back("remote_rejected", static_cast<double>(s.remote_rejected));
  common::append_admission_metrics(*command_admission, "commands", metrics);
}

std::string GatewayMetrics::summary(std::uint64_t late_periods) {
  std::lock_guard lock(last_mutex_);
  take_newest();
  const StatusSnapshot& s = last_;
  const device::LatencyHistogram& latency = last_latency_;
  const device::LatencyHistogram& run = s.motion_to_force_run;
  char line[640];
  std::snprintf(
      line, sizeof(line),
      "ticks %llu, late periods %llu, motion-to-force (last window with commands) n=%llu p50 %.3f "
      "ms p99 %.3f ms, whole run n=%llu p50 %.3f ms p99 %.3f ms max %.3f ms, "
      "peak force %.3f N, renderable %.3f N, commands accepted %llu, rejected nan %llu stale %llu, "
      "silences %llu, engaged %llu, PC removed %.3f mJ",
      static_cast<unsigned long long>(s.ticks), static_cast<unsigned long long>(late_periods),
      static_cast<unsigned long long>(latency.count()), ms(latency.percentile(0.5)),
      ms(latency.percentile(0.99)), static_cast<unsigned long long>(run.count()),
      ms(run.percentile(0.5)), ms(run.percentile(0.99)), ms(run.max()), s.peak_force_n,
      s.renderable_force_n, static_cast<unsigned long long>(s.safety.accepted),
      static_cast<unsigned long long>(s.safety.rejected_non_finite),
      static_cast<unsigned long long>(s.safety.rejected_stale),
      static_cast<unsigned long long>(s.safety.silence_events),
      static_cast<unsigned long long>(s.safety.engage_events), s.passivity_dissipated_j * 1e3);
  return line;
}

}  // namespace fahr::gateway_service
