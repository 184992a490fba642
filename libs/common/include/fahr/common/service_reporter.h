// Publishes a service's ServiceStatus and ServiceEvents from its own
// thread: tick statistics from a TickRecorder (percentiles of period, work
// time and CPU time; periods longer than 1.5x nominal counted as late), the
// transport's QoS events, service-specific metrics and errors. Nothing here
// runs in the service's loop except TickRecorder::push.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "fahr/common/publisher.h"
#include "fahr/common/tick_recorder.h"

namespace fahr::common {

struct ReporterSettings {
  std::string service_name;
  double nominal_rate_hz = 1000.0;
  std::chrono::milliseconds report_period{250};
};

// Adds service-specific figures (name with unit suffix, value) to a report.
using MetricsSource = std::function<void(std::vector<std::pair<std::string, double>>& metrics)>;
// Adds the errors the service has seen since the previous report, each one
// sentence, said once (the source keeps track of what it already gave).
// Called on the reporter's thread: a source that formats text here keeps
// the formatting, and its allocations, off the service's loop.
using ErrorSource = std::function<void(std::vector<std::string>& errors)>;

class ServiceReporter {
 public:
  // Each error of `errors` goes out in the next ServiceEvents and on stderr
  // as "<service_name>: <error>".
  ServiceReporter(Participant& participant, ReporterSettings settings, TickRecorder& ticks,
                  MetricsSource metrics = {}, ErrorSource errors = {});
  ~ServiceReporter();
  ServiceReporter(const ServiceReporter&) = delete;
  ServiceReporter& operator=(const ServiceReporter&) = delete;

  // Publishes one report now (also called by the reporter thread).
  void report();
  void set_state(msg::ServiceState state) { state_.store(state); }
  std::uint64_t late_periods() const { return late_periods_; }
  std::uint64_t ticks() const { return ticks_; }

 private:
  void run();

  Participant& participant_;
  ReporterSettings settings_;
  TickRecorder& recorder_;
  MetricsSource metrics_;
  ErrorSource errors_;
  std::vector<std::string> error_texts_;
  std::atomic<msg::ServiceState> state_{msg::SERVICE_STARTING};
  Publisher<msg::ServiceStatus> status_;
  Publisher<msg::ServiceEvents> events_;
  std::mutex report_mutex_;
  std::int64_t last_start_ns_ = 0;
  std::uint64_t ticks_ = 0;
  std::uint64_t late_periods_ = 0;
  std::uint64_t recorder_dropped_reported_ = 0;
  std::int64_t last_report_ns_ = 0;
  std::vector<std::int64_t> periods_, durations_, cpus_;
  std::vector<msg::TickSpan> spans_;
  std::mutex stop_mutex_;
  std::condition_variable stop_cv_;
  bool stop_ = false;
  std::thread thread_;
};

// Percentiles of a set of durations (the vector is sorted in place).
msg::DurationStats duration_stats(std::vector<std::int64_t>& values_ns);

}  // namespace fahr::common
