// fahr_report: a fahr recording as one self-contained HTML page (inline
// SVG drawn by an inline script; opens offline): the haptic update rate
// over time (the paper's Figure 6c), force against the device's renderable
// limit with lost-track episodes shaded, the device-proxy gap, latency
// CDFs per topic, the FEM step time and deadline misses over time.
//
//   fahr_report FILE.mcap [-o report.html]
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "device_posePubSubTypes.h"
#include "fahr/cli/cli.h"
#include "fahr/common/cdr_bytes.h"
#include "fahr/mcap/reader.h"
#include "force_commandPubSubTypes.h"
#include "page.h"
#include "service_statusPubSubTypes.h"

namespace fahr {
namespace {

template <class T, class PubSub>
bool decode(const mcap::MessageView& m, T& out) {
  return common::decode_cdr<PubSub>(m.data, out);
}

struct Series {
  std::string name;
  std::vector<double> x, y;
};

std::string number(double v) {
  if (!std::isfinite(v)) return "0";
  char text[32];
  std::snprintf(text, sizeof(text), "%.6g", v);
  return text;
}

std::string quoted(const std::string& s) {
  std::string q = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      q += '\\';
      q += c;
    } else if (c == '\n') {
      q += "\\n";
    } else if (static_cast<unsigned char>(c) < 0x20) {
      q += ' ';
    } else if (c == '<') {
      q += "\\u003c";  // never "</script>" inside the script
    } else {
      q += c;
    }
  }
  return q + "\"";
}

// Every k-th point, at most `limit` (the last one kept).
Series thin(Series s, std::size_t limit = 3000) {
  if (s.x.size() <= limit) return s;
  const std::size_t k = (s.x.size() + limit - 1) / limit;
  Series out{s.name, {}, {}};
  for (std::size_t i = 0; i < s.x.size(); i += k) {
    out.x.push_back(s.x[i]);
    out.y.push_back(s.y[i]);
  }
  out.x.push_back(s.x.back());
  out.y.push_back(s.y.back());
  return out;
}

std::string series_json(const Series& s) {
  std::string j = "{\"name\":" + quoted(s.name) + ",\"x\":[";
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (i) j += ',';
    j += number(s.x[i]);
  }
  j += "],\"y\":[";
  for (std::size_t i = 0; i < s.y.size(); ++i) {
    if (i) j += ',';
    j += number(s.y[i]);
  }
  return j + "]}";
}

struct Plot {
  std::string title, note, xlabel, ylabel;
  std::vector<Series> series;
  std::vector<std::pair<double, double>> bands;
  std::string band_name;
  bool y_from_zero = true;
};

std::string plot_json(const Plot& p) {
  std::string j = "{\"title\":" + quoted(p.title) + ",\"note\":" + quoted(p.note) +
                  ",\"xlabel\":" + quoted(p.xlabel) + ",\"ylabel\":" + quoted(p.ylabel) +
                  (p.y_from_zero ? ",\"y0\":0" : "") + ",\"series\":[";
  for (std::size_t i = 0; i < p.series.size(); ++i) {
    if (i) j += ',';
    j += series_json(thin(p.series[i]));
  }
  j += "],\"bandName\":" + quoted(p.band_name) + ",\"bands\":[";
  for (std::size_t i = 0; i < p.bands.size(); ++i) {
    j += (i ? ",[" : "[") + number(p.bands[i].first) + "," + number(p.bands[i].second) + "]";
  }
  return j + "]}";
}

int run(int argc, char** argv) {
  fahr::cli::App app{"fahr_report: a recording as one self-contained HTML page of plots"};
  std::string path, output;
  app.add_option("file", path, "fahr recording (MCAP)")->required();
  app.add_option("-o,--output", output, "the page (default: FILE with .html)");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  if (output.empty()) output = path + ".html";
  const bool tty = isatty(STDERR_FILENO) != 0;

  std::int64_t t0 = 0;
  auto seconds = [&](std::int64_t ns) { return static_cast<double>(ns - t0) * 1e-9; };
  std::vector<std::int64_t> haptic_ticks;
  Series fem_step{"FEM step (tick wall time)", {}, {}};
  std::vector<std::pair<std::int64_t, double>> fem_raw;
  Series force{"|F| commanded", {}, {}}, limit{"renderable limit", {}, {}};
  Series gap{"|device - proxy|", {}, {}};
  std::vector<std::pair<std::int64_t, bool>> lost;
  std::map<std::string, std::vector<double>> latency;
  std::map<std::string, std::vector<std::pair<std::int64_t, double>>> late;
  std::vector<std::pair<std::int64_t, double>> force_raw, limit_raw, gap_raw;
  std::uint64_t seen = 0;
  msg::ServiceEvents events;
  msg::ServiceStatus status;
  msg::DevicePose pose;
  msg::ForceCommand command;
  const auto report = mcap::read_file(path, [&](const mcap::Channel& c,
                                                const mcap::MessageView& m) {
    if (tty && ++seen % 20000 == 0) {
      std::fprintf(stderr, "\rfahr_report: %llu messages read",
                   static_cast<unsigned long long>(seen));
    }
    latency[c.topic].push_back(
        (static_cast<double>(m.log_time) - static_cast<double>(m.publish_time)) * 1e-6);
    if (c.topic == "fahr/ServiceEvents") {
      if (!decode<msg::ServiceEvents, msg::ServiceEventsPubSubType>(m, events)) return;
      const std::string name = events.service_name().to_string();
      for (const auto& span : events.tick_spans()) {
        if (name == "haptic") haptic_ticks.push_back(span.start_ns());
        if (name == "fem")
          fem_raw.emplace_back(span.start_ns(), static_cast<double>(span.duration_ns()) * 1e-6);
      }
    } else if (c.topic == "fahr/ServiceStatus") {
      if (!decode<msg::ServiceStatus, msg::ServiceStatusPubSubType>(m, status)) return;
      late[status.service_name().to_string()].emplace_back(
          static_cast<std::int64_t>(m.publish_time), static_cast<double>(status.late_periods()));
    } else if (c.topic == "fahr/DevicePose") {
      if (!decode<msg::DevicePose, msg::DevicePosePubSubType>(m, pose)) return;
      if (t0 == 0) t0 = pose.header().source_time_ns();
      limit_raw.emplace_back(pose.header().source_time_ns(), pose.renderable_force_n());
    } else if (c.topic == "fahr/ForceCommand") {
      if (!decode<msg::ForceCommand, msg::ForceCommandPubSubType>(m, command)) return;
      const auto& f = command.force_n();
      const auto& g = command.device_minus_proxy_m();
      const std::int64_t ns = command.header().source_time_ns();
      force_raw.emplace_back(ns, std::sqrt(f.x() * f.x() + f.y() * f.y() + f.z() * f.z()));
      gap_raw.emplace_back(ns, 1e3 * std::sqrt(g.x() * g.x() + g.y() * g.y() + g.z() * g.z()));
      lost.emplace_back(ns, command.lost_track());
    }
  });
  if (tty)
    std::fprintf(stderr, "\rfahr_report: %llu messages read\n",
                 static_cast<unsigned long long>(report.messages));
  if (report.messages == 0) {
    std::fprintf(stderr, "fahr_report: %s: no messages (%s)\n", path.c_str(), report.error.c_str());
    return 1;
  }
  if (t0 == 0) t0 = static_cast<std::int64_t>(report.message_start_time);

  std::vector<Plot> plots;
  {
    // Ticks per 50 ms bin, as Hz.
    std::sort(haptic_ticks.begin(), haptic_ticks.end());
    Series rate{"haptic ticks per second (50 ms bins)", {}, {}};
    constexpr std::int64_t kBin = 50'000'000;
    if (!haptic_ticks.empty()) {
      std::int64_t bin = haptic_ticks.front() - (haptic_ticks.front() - t0) % kBin;
      std::size_t n = 0;
      for (std::int64_t ns : haptic_ticks) {
        while (ns >= bin + kBin) {
          rate.x.push_back(seconds(bin + kBin / 2));
          rate.y.push_back(static_cast<double>(n) * 1e9 / static_cast<double>(kBin));
          n = 0;
          bin += kBin;
        }
        ++n;
      }
    }
    plots.push_back({"Haptic update rate over time (Figure 6c)",
                     "From the haptic service's tick spans (ServiceEvents).",
                     "time, s",
                     "update rate, Hz",
                     {rate},
                     {},
                     "",
                     true});
  }
  {
    for (const auto& [ns, v] : force_raw) {
      force.x.push_back(seconds(ns));
      force.y.push_back(v);
    }
    for (const auto& [ns, v] : limit_raw) {
      limit.x.push_back(seconds(ns));
      limit.y.push_back(v);
    }
    std::vector<std::pair<double, double>> bands;
    for (std::size_t i = 0; i < lost.size(); ++i) {
      if (!lost[i].second) continue;
      const std::size_t start = i;
      while (i + 1 < lost.size() && lost[i + 1].second) ++i;
      bands.emplace_back(seconds(lost[start].first), seconds(lost[i].first));
    }
    plots.push_back({"Force and the renderable limit",
                     "ForceCommand force magnitude and the device's renderable force "
                     "(DevicePose); shaded: the device lost track (constraints frozen).",
                     "time, s",
                     "force, N",
                     {force, limit},
                     bands,
                     "lost track",
                     true});
  }
  for (const auto& [ns, v] : gap_raw) {
    gap.x.push_back(seconds(ns));
    gap.y.push_back(v);
  }
  plots.push_back({"Device-proxy gap",
                   "|device - proxy| from each ForceCommand (the grey dummy).",
                   "time, s",
                   "gap, mm",
                   {gap},
                   {},
                   "",
                   true});
  {
    Plot cdf{"Latency CDF per topic",
             "Recorder receive time minus the writer's source time (one host, one clock); "
             "topics with fewer than 100 samples (the latched scene) left out.",
             "latency, ms",
             "fraction of samples",
             {},
             {},
             "",
             true};
    for (auto& [topic, v] : latency) {
      if (v.size() < 100) continue;
      std::sort(v.begin(), v.end());
      Series s{topic, {}, {}};
      const std::size_t points = std::min<std::size_t>(v.size(), 500);
      for (std::size_t k = 0; k < points; ++k) {
        const std::size_t i = k * (v.size() - 1) / (points - 1);
        s.x.push_back(v[i]);
        s.y.push_back(static_cast<double>(i + 1) / static_cast<double>(v.size()));
      }
      cdf.series.push_back(s);
    }
    plots.push_back(cdf);
  }
  std::sort(fem_raw.begin(), fem_raw.end());
  for (const auto& [ns, ms] : fem_raw) {
    fem_step.x.push_back(seconds(ns));
    fem_step.y.push_back(ms);
  }
  plots.push_back({"FEM step time",
                   "Wall time of each FEM tick (ServiceEvents tick spans).",
                   "time, s",
                   "step, ms",
                   {fem_step},
                   {},
                   "",
                   true});
  {
    Plot misses{"Deadline misses over time",
                "Periods longer than 1.5x nominal, counted by each service (ServiceStatus).",
                "time, s",
                "late periods (cumulative)",
                {},
                {},
                "",
                true};
    for (const auto& [name, series] : late) {
      Series s{name, {}, {}};
      for (const auto& [ns, v] : series) {
        s.x.push_back(seconds(ns));
        s.y.push_back(v);
      }
      misses.series.push_back(s);
    }
    plots.push_back(misses);
  }

  std::vector<std::pair<std::string, std::string>> meta = {
      {"recording", path},
      {"messages", std::to_string(report.messages)},
      {"log time",
       number(static_cast<double>(report.message_end_time - report.message_start_time) * 1e-9) +
           " s"},
      {"file valid", report.valid() ? "yes (CRCs checked)" : "no: " + report.error}};
  for (const auto& m : report.metadata) {
    for (const auto& [k, v] : m.values) {
      if (k == "scene_text") continue;
      meta.emplace_back(m.name + " " + k, v);
    }
  }
  std::ofstream out(output);
  out << report::kHead << "{\"meta\":[";
  for (std::size_t i = 0; i < meta.size(); ++i) {
    out << (i ? "," : "") << "[" << quoted(meta[i].first) << "," << quoted(meta[i].second) << "]";
  }
  out << "],\"plots\":[";
  for (std::size_t i = 0; i < plots.size(); ++i) out << (i ? "," : "") << plot_json(plots[i]);
  out << "]}" << report::kTail;
  if (!out) {
    std::fprintf(stderr, "fahr_report: cannot write %s\n", output.c_str());
    return 1;
  }
  std::printf("fahr_report: %s -> %s (%zu plots)\n", path.c_str(), output.c_str(), plots.size());
  return 0;
}

}  // namespace
}  // namespace fahr

int main(int argc, char** argv) {
  try {
    return fahr::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_report: %s\n", e.what());
    return 1;
  }
}
