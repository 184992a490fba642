// ServiceStatus from gateway snapshots.
#include "status_reporter.h"

#include <unistd.h>

#include <cstdio>

#include "fahr/common/vendor.h"

namespace fahr::device_main {

namespace {

msg::DurationStats stats(const device::LatencyHistogram& h) {
  msg::DurationStats s;
  s.count(h.count());
  s.mean_ns(h.mean().count());
  s.p50_ns(h.percentile(0.5).count());
  s.p99_ns(h.percentile(0.99).count());
  s.p999_ns(h.percentile(0.999).count());
  s.max_ns(h.max().count());
  return s;
}

void metric(msg::ServiceStatus& status, const char* name, double value) {
  msg::Metric m;
  m.name(name);
  m.value(value);
  status.metrics().push_back(m);
}

double ms(std::chrono::nanoseconds d) { return static_cast<double>(d.count()) * 1e-6; }

}  // namespace

StatusReporter::StatusReporter(common::Participant& participant, double rate_hz, double nominal_rate_hz,
                               std::string backend)
    : participant_(participant),
      period_s_(1.0 / rate_hz),
      nominal_rate_hz_(nominal_rate_hz),
      backend_(std::move(backend)),
      publisher_(participant) {
  status_.service_id(participant.writer_id());
  status_.service_name("device_gateway");
  char host[64] = {};
  gethostname(host, sizeof(host) - 1);
  status_.host(host);
  status_.pid(static_cast<std::uint32_t>(getpid()));
  status_.dds_vendor(std::string(common::vendor_name(participant.vendor())));
  status_.nominal_rate_hz(nominal_rate_hz_);
  thread_ = std::thread([this] { run(); });
}

StatusReporter::~StatusReporter() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void StatusReporter::run() {
  const auto period = std::chrono::duration<double>(period_s_);
  while (!stop_) {
    std::this_thread::sleep_for(period);
    publish_now();
  }
}

void StatusReporter::publish_now() {
  if (!latest_.fetch()) return;
  last_ = latest_.value();
  const StatusSnapshot& s = last_;
  const bool degraded = s.safety_state == device::SafetyState::kFault || s.late_periods > 0;
  status_.state(degraded ? msg::ServiceState::SERVICE_DEGRADED : msg::ServiceState::SERVICE_RUNNING);
  status_.measured_rate_hz(s.window_s > 0.0 ? static_cast<double>(s.window_ticks) / s.window_s : 0.0);
  status_.ticks(s.ticks);
  status_.period(stats(s.period));
  status_.tick_cpu(stats(s.tick_cpu));
  status_.late_periods(s.late_periods);
  status_.metrics().clear();
  metric(status_, "motion_to_force_count", static_cast<double>(s.motion_to_force.count()));
  metric(status_, "motion_to_force_p50_ms", ms(s.motion_to_force.percentile(0.5)));
  metric(status_, "motion_to_force_p99_ms", ms(s.motion_to_force.percentile(0.99)));
  metric(status_, "motion_to_force_p999_ms", ms(s.motion_to_force.percentile(0.999)));
  metric(status_, "motion_to_force_max_ms", ms(s.motion_to_force.max()));
  metric(status_, "safety_state", static_cast<double>(s.safety_state));
  metric(status_, "renderable_force_n", s.renderable_force_n);
  metric(status_, "peak_force_n", s.peak_force_n);
  metric(status_, "thermal_heat", s.heat);
  metric(status_, "energy_to_hand_mj", s.energy_to_hand_j * 1e3);
  metric(status_, "passivity_dissipated_mj", s.passivity_dissipated_j * 1e3);
  metric(status_, "passivity_active_ticks", static_cast<double>(s.passivity_active_ticks));
  metric(status_, "commands_accepted", static_cast<double>(s.safety.accepted));
  metric(status_, "rejected_non_finite", static_cast<double>(s.safety.rejected_non_finite));
  metric(status_, "rejected_stale", static_cast<double>(s.safety.rejected_stale));
  metric(status_, "rejected_from_future", static_cast<double>(s.safety.rejected_from_future));
  metric(status_, "rejected_out_of_order", static_cast<double>(s.safety.rejected_out_of_order));
  metric(status_, "saturated_ticks", static_cast<double>(s.safety.saturated_ticks));
  metric(status_, "rate_limited_ticks", static_cast<double>(s.safety.rate_limited_ticks));
  metric(status_, "silence_events", static_cast<double>(s.safety.silence_events));
  metric(status_, "remote_rejected", static_cast<double>(s.remote_rejected));
  publisher_.write(status_);
}

std::string StatusReporter::summary() const {
  const StatusSnapshot& s = last_;
  char line[512];
  std::snprintf(line, sizeof(line),
                "ticks %llu, late periods %llu, motion-to-force (last window) n=%llu p50 %.3f ms p99 %.3f ms, "
                "peak force %.3f N, renderable %.3f N, commands accepted %llu, rejected nan %llu stale %llu, "
                "silences %llu, PC removed %.3f mJ",
                static_cast<unsigned long long>(s.ticks), static_cast<unsigned long long>(s.late_periods),
                static_cast<unsigned long long>(s.motion_to_force.count()), ms(s.motion_to_force.percentile(0.5)),
                ms(s.motion_to_force.percentile(0.99)), s.peak_force_n, s.renderable_force_n,
                static_cast<unsigned long long>(s.safety.accepted),
                static_cast<unsigned long long>(s.safety.rejected_non_finite),
                static_cast<unsigned long long>(s.safety.rejected_stale),
                static_cast<unsigned long long>(s.safety.silence_events), s.passivity_dissipated_j * 1e3);
  return line;
}

}  // namespace fahr::device_main
