// fahr_run_summary: listens to a running co-simulation for a fixed time and
// prints what a training-lab run should be judged by: each service's rate,
// late periods and tick CPU time, deadline misses and errors from its
// ServiceEvents, motion-to-force latency (from the gateway's metrics), peak
// force against the device's limit and lost-track episodes (from
// ForceCommand).
//
//   fahr_run_summary --duration-s S [--dds V] [--domain N] [--dds-profile F]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "fahr/common/config_error.h"
#include "fahr/common/stop_signal.h"
#include "fahr/common/subscriber.h"
#include "fahr/common/wire_eigen.h"

namespace {

using namespace fahr;

struct ServiceTally {
  std::string vendor;
  double nominal_hz = 0;
  std::vector<double> measured_hz;
  std::uint64_t ticks = 0;
  std::uint64_t late_periods = 0;
  std::int64_t worst_cpu_p99_ns = 0;
  std::int64_t worst_period_max_ns = 0;
  std::map<std::string, double> metrics;  // newest value of each
  std::map<int, long> qos_events;         // kind -> count
  std::vector<std::string> errors;        // as reported, oldest first
  // (writer, seq) of the ServiceEvents that carried errors: a sample the
  // transport delivers twice adds its errors once.
  std::set<std::pair<std::uint32_t, std::uint64_t>> error_samples;
};

struct Tally {
  std::mutex mutex;
  std::map<std::string, ServiceTally> services;
  std::uint64_t commands = 0;
  double peak_command_n = 0;
  double peak_reaction_n = 0;
  std::uint64_t lost_track_episodes = 0;
  bool lost_track = false;
  double max_gap_m = 0;
  double limit_n = 0;
  double peak_rendered_n = 0;
  std::uint64_t poses = 0;
};

double norm(const msg::Vec3& v) {
  return common::to_eigen(v).norm();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

void print(const Tally& t, double duration_s) {
  std::printf("\n## fahr run summary (%.1f s)\n\n", duration_s);
  std::printf(
      "| service | vendor | nominal Hz | measured Hz (median) | ticks | late periods | tick CPU "
      "p99 us (worst) | period max ms (worst) | deadline misses |\n");
  std::printf("|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const auto& [name, s] : t.services) {
    long misses = 0;
    for (int k : {msg::QOS_REQUESTED_DEADLINE_MISSED, msg::QOS_OFFERED_DEADLINE_MISSED}) {
      auto it = s.qos_events.find(k);
      if (it != s.qos_events.end()) misses += it->second;
    }
    std::printf("| %s | %s | %.0f | %.1f | %llu | %llu | %.1f | %.2f | %ld |\n", name.c_str(),
                s.vendor.c_str(), s.nominal_hz, median(s.measured_hz),
                static_cast<unsigned long long>(s.ticks),
                static_cast<unsigned long long>(s.late_periods),
                static_cast<double>(s.worst_cpu_p99_ns) / 1e3,
                static_cast<double>(s.worst_period_max_ns) / 1e6, misses);
  }
  std::printf("\n| figure | value |\n|---|---:|\n");
  std::printf("| DevicePose samples | %llu |\n", static_cast<unsigned long long>(t.poses));
  std::printf("| ForceCommand samples | %llu |\n", static_cast<unsigned long long>(t.commands));
  std::printf("| device force limit (renderable, last) N | %.2f |\n", t.limit_n);
  std::printf("| peak rendered force N | %.2f |\n", t.peak_rendered_n);
  std::printf("| peak commanded force N | %.2f |\n", t.peak_command_n);
  std::printf("| peak tissue reaction N | %.2f |\n", t.peak_reaction_n);
  std::printf("| lost-track episodes | %llu |\n",
              static_cast<unsigned long long>(t.lost_track_episodes));
  std::printf("| largest device-proxy gap mm | %.2f |\n", t.max_gap_m * 1e3);
  for (const auto& [name, s] : t.services) {
    for (const auto& [metric, value] : s.metrics) {
      if (metric.find("latency") != std::string::npos ||
          metric.find("motion_to_force") != std::string::npos) {
        std::printf("| %s %s | %.3f |\n", name.c_str(), metric.c_str(), value);
      }
    }
  }
  // Only when there were any, so a clean run's summary is as before.
  bool heading = false;
  for (const auto& [name, s] : t.services) {
    for (const std::string& error : s.errors) {
      if (!heading) std::printf("\nErrors the services reported:\n\n");
      heading = true;
      std::printf("- %s: %s\n", name.c_str(), error.c_str());
    }
  }
}

}  // namespace

// A function-try-block: what the set-up before the inner try throws ends in a message too.
int main(int argc, char** argv) try {
  CLI::App app{"Summarise a running fahr co-simulation"};
  std::string dds, domain, profile;
  double duration_s = 10;
  app.add_option("--duration-s", duration_s, "how long to listen (0: until SIGINT or SIGTERM)");
  app.add_option("--dds", dds, "DDS vendor");
  app.add_option("--domain", domain, "DDS domain id");
  app.add_option("--dds-profile", profile, "vendor XML configuration");
  CLI11_PARSE(app, argc, argv);
  common::install_stop_handlers();
  try {
    common::Participant participant(
        common::transport_config_from(dds, domain, profile, "fahr_run_summary"));
    Tally tally;
    common::QosProfile reports = common::QosProfile::for_role(common::TopicRole::kReport);
    common::Subscriber<msg::ServiceStatus> status(
        participant, reports, common::TopicTraits<msg::ServiceStatus>::kName,
        [&](const msg::ServiceStatus& s, const common::SampleInfo&) {
          std::lock_guard lock(tally.mutex);
          auto& t = tally.services[s.service_name().to_string()];
          t.vendor = s.dds_vendor().to_string();
          t.nominal_hz = s.nominal_rate_hz();
          if (s.measured_rate_hz() > 0) t.measured_hz.push_back(s.measured_rate_hz());
          t.ticks = s.ticks();
          t.late_periods = s.late_periods();
          t.worst_cpu_p99_ns = std::max(t.worst_cpu_p99_ns, s.tick_cpu().p99_ns());
          t.worst_period_max_ns = std::max(t.worst_period_max_ns, s.period().max_ns());
          // A report window with no samples of a windowed figure (the
          // gateway's final report after its last in-loop one) would hide
          // the run's values: keep the newest window that has samples.
          bool empty_window = false;
          for (const auto& m : s.metrics()) {
            const std::string name = m.name().to_string();
            if (name.size() > 6 && name.compare(name.size() - 6, 6, "_count") == 0 &&
                m.value() == 0)
              empty_window = true;
          }
          if (!empty_window || t.metrics.empty()) {
            for (const auto& m : s.metrics()) t.metrics[m.name().to_string()] = m.value();
          }
        });
    common::Subscriber<msg::ServiceEvents> events(
        participant, reports, common::TopicTraits<msg::ServiceEvents>::kName,
        [&](const msg::ServiceEvents& e, const common::SampleInfo&) {
          std::lock_guard lock(tally.mutex);
          auto& t = tally.services[e.service_name().to_string()];
          for (const auto& q : e.qos_events())
            t.qos_events[q.kind()] += std::max(q.total_count_change(), 0);
          if (!e.errors().empty() &&
              t.error_samples.emplace(e.header().writer_id(), e.header().seq()).second) {
            for (const auto& error : e.errors()) t.errors.push_back(error.text().to_string());
          }
        });
    common::Subscriber<msg::ForceCommand> commands(
        participant, common::QosProfile::for_role(common::TopicRole::kServoStream),
        common::TopicTraits<msg::ForceCommand>::kName,
        [&](const msg::ForceCommand& c, const common::SampleInfo&) {
          std::lock_guard lock(tally.mutex);
          ++tally.commands;
          tally.peak_command_n = std::max(tally.peak_command_n, norm(c.force_n()));
          tally.peak_reaction_n = std::max(tally.peak_reaction_n, c.tissue_reaction_n());
          if (c.lost_track() && !tally.lost_track) ++tally.lost_track_episodes;
          tally.lost_track = c.lost_track();
          tally.max_gap_m = std::max(tally.max_gap_m, norm(c.device_minus_proxy_m()));
        });
    common::Subscriber<msg::DevicePose> poses(
        participant, common::QosProfile::for_role(common::TopicRole::kServoStream),
        common::TopicTraits<msg::DevicePose>::kName,
        [&](const msg::DevicePose& p, const common::SampleInfo&) {
          std::lock_guard lock(tally.mutex);
          ++tally.poses;
          tally.limit_n = p.renderable_force_n();
          tally.peak_rendered_n = std::max(tally.peak_rendered_n, norm(p.rendered_force_n()));
        });
    // Until the duration has passed (0: until SIGINT/SIGTERM), or a stop
    // signal comes first (fahr_lab stops a station that way): the summary
    // of what was heard is printed either way.
    const auto started = std::chrono::steady_clock::now();
    const auto elapsed_s = [&] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    };
    while (!common::stop_requested() && (duration_s <= 0 || elapsed_s() < duration_s)) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    std::lock_guard lock(tally.mutex);
    print(tally, elapsed_s());
    return 0;
  } catch (const common::ConfigError& e) {
    std::fprintf(stderr, "fahr_run_summary: %s\n", e.what());
    return 2;
  }
} catch (const std::exception& e) {
  std::fprintf(stderr, "fahr_run_summary: %s\n", e.what());
  return 1;
}
