// fahr_run_summary: listens to a running co-simulation for a fixed time and
// prints what a training-lab run should be judged by: each service's rate,
// late periods and tick CPU time, deadline misses and errors from its
// ServiceEvents, motion-to-force latency (from the gateway's metrics), peak
// force against the device's limit and lost-track episodes (from
// ForceCommand). A service whose reports stop for more than a second has a
// silence (a gap); one silent at the end is dead and gets no rate; one that
// comes back as another participant was restarted.
//
//   fahr_run_summary --duration-s S [--dds V] [--domain N] [--dds-profile F]
//                    [--tick-spans FILE]
//
// --tick-spans FILE: also writes every tick span the services report
// (ServiceEvents: a service's per-tick wall start, wall duration and thread
// CPU time) to FILE as CSV, so a bench can split one run's ticks by time.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "fahr/cli/cli.h"
#include "fahr/common/config_error.h"
#include "fahr/common/stop_signal.h"
#include "fahr/common/subscriber.h"
#include "fahr/common/wire_eigen.h"

namespace {

using namespace fahr;

// A gap longer than this between two ServiceStatus of a service (any of
// its instances) is a silence: a dead, stopped or stalled service (reports
// come 4 times a second).
constexpr double kSilenceS = 1.0;

struct Silence {
  double from_s = 0;     // the last report before it, s after the summary began
  double to_s = -1;      // the first report after it; < 0: still silent at the end
  bool restart = false;  // it came back as another participant (a restart)
};

struct ServiceTally {
  // Each ServiceStatus's arrival, s after the summary began, and its writer.
  double last_report_s = -1;
  std::uint32_t last_writer = 0;
  bool stopping = false;  // the newest report said SERVICE_STOPPING
  std::set<std::uint32_t> writers;
  std::vector<Silence> silences;
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
  std::map<int, std::uint64_t> command_reasons;  // ForceCommand.reason -> samples
};

const char* reason_name(int reason) {
  switch (reason) {
    case msg::FORCE_RENDERED:
      return "rendered";
    case msg::FORCE_RESUMING:
      return "resuming (slew)";
    case msg::FORCE_TISSUE_LOST:
      return "tissue lost (ramp to zero)";
    case msg::FORCE_DEVICE_NOT_ENABLED:
      return "device not enabled (zero)";
  }
  return "unknown";
}

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
      "p99 us (worst) | period max ms (worst) | deadline misses | silences | restarts |\n");
  std::printf("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const auto& [name, s] : t.services) {
    long misses = 0;
    for (int k : {msg::QOS_REQUESTED_DEADLINE_MISSED, msg::QOS_OFFERED_DEADLINE_MISSED}) {
      auto it = s.qos_events.find(k);
      if (it != s.qos_events.end()) misses += it->second;
    }
    // A service silent at the end (and not stopping) has no rate: it is dead.
    const bool dead = !s.silences.empty() && s.silences.back().to_s < 0;
    char rate[64];
    if (dead) {
      std::snprintf(rate, sizeof(rate), "dead since %.2f s", s.silences.back().from_s);
    } else {
      std::snprintf(rate, sizeof(rate), "%.1f", median(s.measured_hz));
    }
    std::printf("| %s | %s | %.0f | %s | %llu | %llu | %.1f | %.2f | %ld | %zu | %zu |\n",
                name.c_str(), s.vendor.c_str(), s.nominal_hz, rate,
                static_cast<unsigned long long>(s.ticks),
                static_cast<unsigned long long>(s.late_periods),
                static_cast<double>(s.worst_cpu_p99_ns) / 1e3,
                static_cast<double>(s.worst_period_max_ns) / 1e6, misses, s.silences.size(),
                s.writers.empty() ? std::size_t{0} : s.writers.size() - 1);
  }
  bool gaps = false;
  for (const auto& [name, s] : t.services) {
    for (const Silence& g : s.silences) {
      if (!gaps) std::printf("\nGaps (no ServiceStatus for more than %.1f s):\n\n", kSilenceS);
      gaps = true;
      if (g.to_s < 0) {
        std::printf("- %s: silent from %.2f s to the end (dead)\n", name.c_str(), g.from_s);
      } else {
        std::printf("- %s: silent from %.2f s to %.2f s (%.2f s), back %s\n", name.c_str(),
                    g.from_s, g.to_s, g.to_s - g.from_s,
                    g.restart ? "as a new participant (restarted)" : "as the same participant");
      }
    }
  }
  std::printf("\n| figure | value |\n|---|---:|\n");
  std::printf("| DevicePose samples | %llu |\n", static_cast<unsigned long long>(t.poses));
  std::printf("| ForceCommand samples | %llu |\n", static_cast<unsigned long long>(t.commands));
  for (const auto& [reason, count] : t.command_reasons) {
    if (reason == msg::FORCE_RENDERED) continue;
    std::printf("| ForceCommand samples: %s | %llu |\n", reason_name(reason),
                static_cast<unsigned long long>(count));
  }
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
  fahr::cli::App app{"Summarise a running fahr co-simulation"};
  std::string dds, domain, profile;
  double duration_s = 10;
  app.add_option("--duration-s", duration_s, "how long to listen (0: until SIGINT or SIGTERM)");
  app.add_option("--dds", dds, "DDS vendor");
  app.add_option("--domain", domain, "DDS domain id");
  app.add_option("--dds-profile", profile, "vendor XML configuration");
  std::string security;
  app.add_option("--security", security,
                 "DDS Security: the station's folder "
                 "(deployment/security/make_station_security.sh; default $FAHR_DDS_SECURITY)");
  std::string spans_path;
  app.add_option("--tick-spans", spans_path,
                 "write every reported tick span to this CSV file "
                 "(service,tick,start_ns,duration_ns,cpu_ns)");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  common::install_stop_handlers();
  // Closed at exit; written under the tally's mutex, off every service's loop.
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> spans_file(nullptr, &std::fclose);
  if (!spans_path.empty()) {
    spans_file.reset(std::fopen(spans_path.c_str(), "w"));
    if (!spans_file) {
      std::fprintf(stderr, "fahr_run_summary: --tick-spans: cannot write '%s'\n",
                   spans_path.c_str());
      return 2;
    }
    std::fprintf(spans_file.get(), "service,tick,start_ns,duration_ns,cpu_ns\n");
  }
  try {
    common::Participant participant(
        common::transport_config_from(dds, domain, profile, "fahr_run_summary", security));
    Tally tally;
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    common::QosProfile reports = common::QosProfile::for_role(common::TopicRole::kReport);
    common::Subscriber<msg::ServiceStatus> status(
        participant, reports, common::TopicTraits<msg::ServiceStatus>::kName,
        [&](const msg::ServiceStatus& s, const common::SampleInfo&) {
          std::lock_guard lock(tally.mutex);
          auto& t = tally.services[s.service_name().to_string()];
          const double now_s = std::chrono::duration<double>(Clock::now() - start).count();
          const std::uint32_t writer = s.header().writer_id();
          if (!t.silences.empty() && t.silences.back().to_s < 0) {
            t.silences.back().to_s = now_s;
            t.silences.back().restart = writer != t.last_writer;
          } else if (t.last_report_s >= 0 && now_s - t.last_report_s > kSilenceS) {
            t.silences.push_back({t.last_report_s, now_s, writer != t.last_writer});
          }
          t.last_report_s = now_s;
          t.last_writer = writer;
          t.writers.insert(writer);
          t.stopping = s.state() == msg::SERVICE_STOPPING;
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
          if (spans_file) {
            for (const auto& span : e.tick_spans()) {
              std::fprintf(spans_file.get(), "%s,%llu,%lld,%lld,%lld\n",
                           e.service_name().to_string().c_str(),
                           static_cast<unsigned long long>(span.tick()),
                           static_cast<long long>(span.start_ns()),
                           static_cast<long long>(span.duration_ns()),
                           static_cast<long long>(span.cpu_ns()));
            }
          }
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
          ++tally.command_reasons[static_cast<int>(c.reason())];
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
    // Silent at the end, without having said it stops: dead (or stalled).
    const double end_s = std::chrono::duration<double>(Clock::now() - start).count();
    for (auto& [name, t] : tally.services) {
      if (t.last_report_s >= 0 && !t.stopping && end_s - t.last_report_s > kSilenceS &&
          (t.silences.empty() || t.silences.back().to_s >= 0)) {
        t.silences.push_back({t.last_report_s, -1, false});
      }
    }
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
