// Status and event reports, built off the service's loop.
#include "fahr/common/service_reporter.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <numeric>

#include "fahr/common/clock.h"

namespace fahr::common {

msg::DurationStats duration_stats(std::vector<std::int64_t>& values_ns) {
  msg::DurationStats stats;
  if (values_ns.empty()) return stats;
  std::sort(values_ns.begin(), values_ns.end());
  auto at = [&](double q) {
    return values_ns[static_cast<std::size_t>(q * static_cast<double>(values_ns.size() - 1))];
  };
  stats.count(values_ns.size());
  stats.mean_ns(std::accumulate(values_ns.begin(), values_ns.end(), std::int64_t{0}) /
                static_cast<std::int64_t>(values_ns.size()));
  stats.p50_ns(at(0.5));
  stats.p99_ns(at(0.99));
  stats.p999_ns(at(0.999));
  stats.max_ns(values_ns.back());
  return stats;
}

namespace {
// Bounds of idl/fahr/service_status.idl.
constexpr std::size_t kMaxSpansPerReport = 1024;
constexpr std::size_t kMaxQosEventsPerReport = 128;
constexpr std::size_t kMaxMetrics = 48;
constexpr std::size_t kMaxErrorsPerReport = 8;
constexpr std::size_t kMaxErrorChars = 200;

msg::QosEventKind to_msg(EventKind kind) {
  return static_cast<msg::QosEventKind>(static_cast<int>(kind));
}

std::string host_name() {
  char name[256] = {};
  gethostname(name, sizeof(name) - 1);
  return name;
}
}  // namespace

ServiceReporter::ServiceReporter(Participant& participant, ReporterSettings settings,
                                 TickRecorder& ticks, MetricsSource metrics, ErrorSource errors)
    : participant_(participant),
      settings_(std::move(settings)),
      recorder_(ticks),
      metrics_(std::move(metrics)),
      errors_(std::move(errors)),
      status_(participant),
      events_(participant),
      last_report_ns_(monotonic_now_ns()),
      thread_([this] { run(); }) {}

ServiceReporter::~ServiceReporter() {
  {
    std::lock_guard lock(stop_mutex_);
    stop_ = true;
  }
  stop_cv_.notify_all();
  thread_.join();
  // The last reports must reach a recorder before the writers go: a
  // reliable sample still unacknowledged at deletion is lost.
  status_.wait_for_acks(std::chrono::milliseconds(500));
  events_.wait_for_acks(std::chrono::milliseconds(500));
}

void ServiceReporter::run() {
  std::unique_lock lock(stop_mutex_);
  while (!stop_cv_.wait_for(lock, settings_.report_period, [this] { return stop_; })) {
    lock.unlock();
    report();
    lock.lock();
  }
}

void ServiceReporter::report() {
  std::lock_guard lock(report_mutex_);
  periods_.clear();
  durations_.clear();
  cpus_.clear();
  spans_.clear();
  const auto nominal_ns = static_cast<std::int64_t>(1e9 / settings_.nominal_rate_hz);
  const std::int64_t wall_offset_ns = wall_now_ns() - monotonic_now_ns();
  const std::uint64_t recorder_dropped = recorder_.dropped();
  auto dropped_spans = static_cast<std::uint32_t>(recorder_dropped - recorder_dropped_reported_);
  recorder_dropped_reported_ = recorder_dropped;
  recorder_.drain([&](const TickRecord& r) {
    ++ticks_;
    if (last_start_ns_ != 0) {
      const std::int64_t period = r.start_ns - last_start_ns_;
      periods_.push_back(period);
      // Counted here, not by the vendor: Fast DDS 2.9 deadline events are
      // unreliable below ~5 ms (dependency-facts.md).
      if (period * 2 > nominal_ns * 3) ++late_periods_;
    }
    last_start_ns_ = r.start_ns;
    durations_.push_back(r.duration_ns);
    cpus_.push_back(r.cpu_ns);
    if (spans_.size() < kMaxSpansPerReport) {
      msg::TickSpan span;
      span.tick(r.tick);
      span.start_ns(r.start_ns + wall_offset_ns);
      span.duration_ns(r.duration_ns);
      span.cpu_ns(r.cpu_ns);
      spans_.push_back(span);
    } else {
      ++dropped_spans;
    }
  });
  const std::int64_t now_ns = monotonic_now_ns();
  const double window_s = static_cast<double>(now_ns - last_report_ns_) * 1e-9;
  last_report_ns_ = now_ns;

  msg::ServiceStatus status;
  status.service_id(participant_.writer_id());
  status.service_name(settings_.service_name);
  status.host(host_name());
  status.pid(static_cast<std::uint32_t>(getpid()));
  status.dds_vendor(std::string(vendor_name(participant_.vendor())));
  status.state(state_.load());
  status.nominal_rate_hz(settings_.nominal_rate_hz);
  status.measured_rate_hz(window_s > 0 ? static_cast<double>(durations_.size()) / window_s : 0.0);
  status.ticks(ticks_);
  status.late_periods(late_periods_);
  status.period(duration_stats(periods_));
  status.tick_cpu(duration_stats(cpus_));
  {
    // Each writer's sent count first ("sent <topic>"), so the bound never
    // cuts them; then the service's own figures.
    std::vector<std::pair<std::string, double>> figures;
    participant_.for_each_sent([&](std::string_view topic, std::uint64_t sent) {
      figures.emplace_back("sent " + std::string(topic), static_cast<double>(sent));
    });
    if (metrics_) metrics_(figures);
    for (const auto& [name, value] : figures) {
      if (status.metrics().size() >= kMaxMetrics) break;
      msg::Metric metric;
      metric.name(name);
      metric.value(value);
      status.metrics().push_back(metric);
    }
  }
  status_.write(status);

  msg::ServiceEvents events;
  events.service_id(participant_.writer_id());
  events.service_name(settings_.service_name);
  std::uint32_t dropped_events = 0;
  dropped_events +=
      static_cast<std::uint32_t>(participant_.events().drain([&](const TransportEvent& e) {
        if (events.qos_events().size() >= kMaxQosEventsPerReport) {
          ++dropped_events;
          return;
        }
        msg::QosEvent q;
        q.time_ns(e.time_ns);
        q.kind(to_msg(e.kind));
        q.topic(std::string(e.topic_name()));
        q.total_count(e.total_count);
        q.total_count_change(e.total_count_change);
        q.current_count(e.current_count);
        q.not_alive_count(e.not_alive_count);
        events.qos_events().push_back(q);
      }));
  error_texts_.clear();
  if (errors_) errors_(error_texts_);
  for (const std::string& text : error_texts_) {
    std::fprintf(stderr, "%s: %s\n", settings_.service_name.c_str(), text.c_str());
    if (events.errors().size() >= kMaxErrorsPerReport) {
      ++dropped_events;
      continue;
    }
    msg::ServiceError error;
    error.time_ns(wall_now_ns());
    error.text(text.substr(0, kMaxErrorChars));
    events.errors().push_back(error);
  }
  events.dropped_events(dropped_events);
  events.dropped_spans(dropped_spans);
  events.tick_spans(spans_);
  events_.write(events);
}

}  // namespace fahr::common
