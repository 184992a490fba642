// fahr_trace: turns a fahr recording (fahr_logger's MCAP) into Chrome trace
// JSON that Perfetto and chrome://tracing open, and prints the whole run's
// latency figures (every tick, not a report window).
//
//   fahr_trace FILE.mcap [-o trace.json]
//
// Tracks: one process per service (from ServiceEvents), a "tick" thread of
// slices from its tick spans (wall start and duration; args: CPU time),
// a "samples" thread with one short slice per DevicePose (gateway) and
// ForceCommand (haptic) at its source time. Flows follow each answered
// DevicePose: its slice -> the haptic tick that wrote the ForceCommand ->
// the ForceCommand -> the first gateway servo tick that started after the
// command reached the recorder (the recorder's receive time stands in for
// the gateway's, which is not recorded). Counters: motion-to-force latency,
// each topic's receive minus source time, the services' measured rates and
// late periods.
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "deformation_statePubSubTypes.h"
#include "device_posePubSubTypes.h"
#include "fahr/cli/cli.h"
#include "fahr/common/cdr_bytes.h"
#include "fahr/common/wire_header.h"
#include "fahr/mcap/reader.h"
#include "force_commandPubSubTypes.h"
#include "service_statusPubSubTypes.h"

namespace fahr {
namespace {

template <class T, class PubSub>
bool decode(const mcap::MessageView& m, T& out) {
  return common::decode_cdr<PubSub>(m.data, out);
}

struct Tick {
  std::int64_t start_ns, duration_ns, cpu_ns;
  std::uint64_t tick;
};

struct Service {
  std::string name;
  int pid = 0;
  std::vector<Tick> ticks;  // sorted by start
};

struct Pose {
  std::int64_t source_ns = 0;
  double force[3] = {0, 0, 0};  // rendered at this servo tick, N
};

struct Command {
  std::uint64_t pose_seq = 0;
  std::int64_t source_ns = 0, log_ns = 0;
  std::uint32_t writer_id = 0;
  std::uint64_t fem_step = 0;
};

// A DeformationState the recorder kept (the recorder may keep one in N).
struct State {
  std::uint32_t writer_id = 0;
  std::uint64_t step = 0;
  std::int64_t source_ns = 0;
  double step_s = 0;
};

// The clock of each service's host against the recorder's, from the
// clock.txt fahr_lab writes in the recorder's run folder (--clock): a time a
// service stamped, minus offset_ms, is on the recorder's clock, within
// error_ms. Without the file every writer counts as on the recorder's clock.
struct HostClock {
  std::string host;
  double offset_ms = 0;
  double error_ms = 0;  // < 0: unknown (the host never answered an echo)
};

struct Clocks {
  bool given = false;
  std::map<std::string, HostClock> by_service;
  HostClock of(const std::string& service) const {
    if (!given) return {};
    auto it = by_service.find(service);
    return it == by_service.end() ? HostClock{"?", 0, -1} : it->second;
  }
};

Clocks read_clocks(const std::string& path) {
  Clocks clocks;
  if (path.empty()) return clocks;
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path);
  clocks.given = true;
  std::map<std::string, HostClock> hosts;
  std::vector<std::pair<std::string, std::string>> services;
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string kind, a, b, key1, key2;
    words >> kind >> a >> b;
    if (kind == "host") {
      HostClock h{a, 0, -1};
      words >> key1 >> h.offset_ms >> key2 >> h.error_ms;
      if (key1 == "offset_ms" && key2 == "error_ms") hosts[a] = h;
    } else if (kind == "service") {
      services.emplace_back(a, b);
    }
  }
  for (const auto& [service, host] : services) {
    auto it = hosts.find(host);
    clocks.by_service[service] = it == hosts.end() ? HostClock{host, 0, -1} : it->second;
  }
  return clocks;
}

// The error of a difference of two stamps made on hosts a and b: none on one
// host, else the sum of both hosts' errors against the recorder; < 0 unknown.
double pair_error_ms(const HostClock& a, const HostClock& b) {
  if (a.host == b.host) return a.error_ms < 0 ? -1 : 0;
  if (a.error_ms < 0 || b.error_ms < 0) return -1;
  return a.error_ms + b.error_ms;
}

std::string clock_note(double error_ms) {
  if (error_ms == 0) return "";
  char text[96];
  std::snprintf(text, sizeof text, "  (clocks: +-%.3f ms)", error_ms);
  return text;
}

constexpr double kFeltStepN = 0.1;  // a force step a hand notices, N a servo tick

struct Percentiles {
  std::size_t n = 0;
  double p50 = 0, p99 = 0, p999 = 0, max = 0, mean = 0, stddev = 0;
};

Percentiles percentiles(std::vector<double> v) {
  Percentiles p;
  if (v.empty()) return p;
  std::sort(v.begin(), v.end());
  auto at = [&](double q) {
    return v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))];
  };
  p.n = v.size();
  p.p50 = at(0.5);
  p.p99 = at(0.99);
  p.p999 = at(0.999);
  p.max = v.back();
  double sum = 0, sq = 0;
  for (double x : v) sum += x;
  p.mean = sum / static_cast<double>(v.size());
  for (double x : v) sq += (x - p.mean) * (x - p.mean);
  p.stddev = std::sqrt(sq / static_cast<double>(v.size()));
  return p;
}

// Chrome trace JSON, written as it goes (one event per line).
class TraceWriter {
 public:
  explicit TraceWriter(const std::string& path) : out_(path) {
    out_ << "{\"displayTimeUnit\":\"ms\",\"traceEvents\":[\n";
  }
  ~TraceWriter() { out_ << "\n]}\n"; }
  bool ok() const { return static_cast<bool>(out_); }
  void raw(const std::string& event) {
    if (count_++ > 0) out_ << ",\n";
    out_ << event;
  }
  // Microseconds relative to the first event, with ns resolution.
  std::string ts(std::int64_t ns) const {
    char text[40];
    std::snprintf(text, sizeof(text), "%.3f", static_cast<double>(ns - origin_ns) * 1e-3);
    return text;
  }
  std::int64_t origin_ns = 0;
  std::size_t count() const { return count_; }

 private:
  std::ofstream out_;
  std::size_t count_ = 0;
};

std::string quoted(const std::string& s) {
  std::string q = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') q += '\\';
    q += c;
  }
  return q + "\"";
}

// What the trainee feels, over the whole run: the largest change of the
// rendered force from one servo tick to the next (DevicePose.rendered_force_n
// of consecutive poses), and how old the FEM state behind each ForceCommand
// was when the haptic service used it: the command's write time minus the
// DeformationState's own write time where the recorder kept that state,
// else the end of the FEM tick that wrote it (the recorder may keep one
// state in N, and a starved one loses most of them). The FEM's tick spans
// give every step's time; the DeformationStates the recorder kept tie FEM
// steps to its ticks. The youngest age is taken over the states whose write
// was recorded only: a tick's end comes after its write, and a state used
// while a starved FEM thread was still finishing its tick would seem used
// before it was written. Ages are on the writers' clocks (one clock
// when the hosts are namespaces of one machine; across machines only within
// their clock error).
void print_felt(const std::map<std::uint64_t, Pose>& poses, const std::vector<Command>& commands,
                const std::vector<State>& states, const std::map<std::uint32_t, Service>& services,
                const Clocks& clocks) {
  std::vector<double> steps;
  std::size_t over = 0;
  for (auto it = poses.begin(); it != poses.end(); ++it) {
    auto next = std::next(it);
    if (next == poses.end() || next->first != it->first + 1) continue;
    double sq = 0;
    for (int k = 0; k < 3; ++k) sq += std::pow(next->second.force[k] - it->second.force[k], 2);
    steps.push_back(std::sqrt(sq));
    if (steps.back() > kFeltStepN + 1e-6) ++over;  // the gate's own 0.1 N steps pass
  }
  std::printf("\nwhat the trainee feels:\n");
  if (!steps.empty()) {
    const auto p = percentiles(steps);
    std::printf(
        "  force step per servo tick:  n %zu  p99 %.4f N  p99.9 %.4f N  max %.4f N  ticks > %.1f N "
        "%zu (%.3f %%)\n",
        p.n, p.p99, p.p999, p.max, kFeltStepN, over,
        100.0 * static_cast<double>(over) / static_cast<double>(p.n));
  }
  // The FEM: the service named fem with the most ticks, and its states.
  const Service* fem = nullptr;
  std::uint32_t fem_id = 0;
  for (const auto& [id, s] : services) {
    if (s.name == "fem" && (fem == nullptr || s.ticks.size() > fem->ticks.size())) {
      fem = &s;
      fem_id = id;
    }
  }
  if (fem == nullptr || fem->ticks.empty() || commands.empty()) {
    std::printf("  FEM state age: no FEM ticks or commands recorded\n");
    return;
  }
  // Tick index -> position; step -> tick from the kept states (the most
  // common difference: a step is written in the tick that made it).
  std::map<std::uint64_t, std::size_t> tick_position;
  for (std::size_t i = 0; i < fem->ticks.size(); ++i) tick_position[fem->ticks[i].tick] = i;
  std::map<std::int64_t, std::size_t> offsets;
  std::map<std::uint64_t, std::int64_t> written_ns;  // step -> its state's write
  double period_s = 0;
  for (const auto& st : states) {
    if (st.writer_id != fem_id) continue;
    period_s = st.step_s;
    written_ns[st.step] = st.source_ns;
    auto after = std::upper_bound(fem->ticks.begin(), fem->ticks.end(), st.source_ns,
                                  [](std::int64_t v, const Tick& t) { return v < t.start_ns; });
    if (after == fem->ticks.begin()) continue;
    const Tick& t = *(after - 1);
    if (st.source_ns > t.start_ns + t.duration_ns) continue;
    ++offsets[static_cast<std::int64_t>(t.tick) - static_cast<std::int64_t>(st.step)];
  }
  if (offsets.empty() || period_s <= 0) {
    std::printf("  FEM state age: no DeformationState inside a FEM tick recorded\n");
    return;
  }
  const std::int64_t offset =
      std::max_element(offsets.begin(), offsets.end(), [](const auto& a, const auto& b) {
        return a.second < b.second;
      })->first;
  std::vector<std::int64_t> ends;
  ends.reserve(fem->ticks.size());
  for (const auto& t : fem->ticks) ends.push_back(t.start_ns + t.duration_ns);
  std::sort(ends.begin(), ends.end());
  const double limit_ms = 3.0 * period_s * 1e3;
  std::vector<double> ages_ms, behind;
  std::size_t old = 0, far_behind = 0, unknown = 0, with_write = 0;
  double youngest_written_ms = std::numeric_limits<double>::infinity();
  std::map<std::uint64_t, bool> used;
  for (const auto& c : commands) {
    if (c.fem_step == 0) continue;  // before the first state
    used[c.fem_step] = true;
    const auto tick = static_cast<std::int64_t>(c.fem_step) + offset;
    auto at = tick_position.find(static_cast<std::uint64_t>(std::max<std::int64_t>(tick, 0)));
    if (tick < 0 || at == tick_position.end()) {
      ++unknown;
      continue;
    }
    const Tick& t = fem->ticks[at->second];
    const auto write = written_ns.find(c.fem_step);
    const bool recorded = write != written_ns.end();
    const double age_ms =
        static_cast<double>(c.source_ns - (recorded ? write->second : t.start_ns + t.duration_ns)) *
        1e-6;
    ages_ms.push_back(age_ms);
    if (recorded) {
      youngest_written_ms = std::min(youngest_written_ms, age_ms);
      ++with_write;
    }
    if (age_ms > limit_ms) ++old;
    // States the FEM had written after this one by the time it was used.
    const auto newer = std::upper_bound(ends.begin(), ends.end(), c.source_ns) -
                       std::upper_bound(ends.begin(), ends.end(), t.start_ns + t.duration_ns);
    behind.push_back(static_cast<double>(std::max<std::ptrdiff_t>(newer, 0)));
    if (newer > 3) ++far_behind;
  }
  if (ages_ms.empty()) {
    std::printf("  FEM state age: no command used a FEM state with a recorded tick\n");
    return;
  }
  const double age_error = pair_error_ms(clocks.of("fem"), clocks.of("haptic"));
  if (age_error < 0) {
    std::printf("  FEM state age: not printed: the FEM's or the haptic host's clock is unknown\n");
    return;
  }
  const auto a = percentiles(ages_ms);
  const auto b = percentiles(behind);
  const auto n = static_cast<double>(a.n);
  char youngest[96] = "min - (no used state's write recorded)";
  if (with_write > 0)
    std::snprintf(youngest, sizeof(youngest), "min %.3f ms (%zu with the write recorded)",
                  youngest_written_ms, with_write);
  std::printf(
      "  FEM state age at use:       n %zu  %s  p50 %.3f ms  p99 %.3f ms  max %.3f ms  "
      "> 3 periods (%.1f ms) %zu (%.3f %%)%s\n",
      a.n, youngest, a.p50, a.p99, a.max, limit_ms, old, 100.0 * static_cast<double>(old) / n,
      clock_note(age_error).c_str());
  std::printf(
      "  newer FEM states written:   p50 %.0f  p99 %.0f  max %.0f  ticks on a state > 3 behind %zu "
      "(%.3f %%)\n",
      b.p50, b.p99, b.max, far_behind, 100.0 * static_cast<double>(far_behind) / n);
  // States written while the haptic service answered poses.
  std::int64_t first_ns = INT64_MAX, last_ns = INT64_MIN;
  for (const auto& c : commands) {
    first_ns = std::min(first_ns, c.source_ns);
    last_ns = std::max(last_ns, c.source_ns);
  }
  const auto written = std::upper_bound(ends.begin(), ends.end(), last_ns) -
                       std::lower_bound(ends.begin(), ends.end(), first_ns);
  std::printf(
      "  FEM states written while commands were %td, used by a ForceCommand %zu, commands without "
      "a tick %zu\n",
      written, used.size(), unknown);
}

int run(int argc, char** argv) {
  fahr::cli::App app{"fahr_trace: a recording as a Chrome trace, and its latency figures"};
  std::string path, output;
  app.add_option("file", path, "fahr recording (MCAP)")->required();
  app.add_option("-o,--output", output, "trace JSON (default: FILE with .trace.json)");
  std::string clock_file;
  app.add_option("--clock", clock_file,
                 "fahr_lab's clock.txt from the recorder's host: the writers' clocks against it");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  const Clocks clocks = read_clocks(clock_file);
  if (output.empty()) output = path + ".trace.json";
  const bool tty = isatty(STDERR_FILENO) != 0;

  // One pass over the file: what the trace and the figures need.
  std::map<std::uint32_t, Service> services;  // by writer_id
  std::map<std::uint64_t, Pose> poses;        // by seq (one gateway)
  std::uint32_t gateway_id = 0;
  std::vector<Command> commands;
  // Receive minus source time per topic and writer, as stamped.
  std::map<std::pair<std::string, std::uint32_t>, std::vector<double>> topic_latency_ms;
  std::map<std::uint32_t, std::vector<std::pair<std::int64_t, double>>> late_periods;
  std::map<std::uint32_t, std::vector<std::pair<std::int64_t, double>>> rates;
  std::vector<std::int64_t> pose_times;
  std::uint64_t seen = 0;
  msg::ServiceEvents events;
  msg::ServiceStatus status;
  msg::DevicePose pose;
  msg::ForceCommand command;
  msg::DeformationState state;
  std::vector<State> states;
  const auto report = mcap::read_file(path, [&](const mcap::Channel& c,
                                                const mcap::MessageView& m) {
    if (tty && ++seen % 20000 == 0) {
      std::fprintf(stderr, "\rfahr_trace: %llu messages read",
                   static_cast<unsigned long long>(seen));
    }
    const auto wire = common::read_wire_header(m.data, false);
    topic_latency_ms[{c.topic, wire ? wire->writer_id : 0}].push_back(
        (static_cast<double>(m.log_time) - static_cast<double>(m.publish_time)) * 1e-6);
    if (c.topic == "fahr/ServiceEvents") {
      if (!decode<msg::ServiceEvents, msg::ServiceEventsPubSubType>(m, events)) return;
      auto& s = services[events.header().writer_id()];
      s.name = events.service_name().to_string();
      for (const auto& span : events.tick_spans()) {
        s.ticks.push_back({span.start_ns(), span.duration_ns(), span.cpu_ns(), span.tick()});
      }
    } else if (c.topic == "fahr/ServiceStatus") {
      if (!decode<msg::ServiceStatus, msg::ServiceStatusPubSubType>(m, status)) return;
      const auto id = status.header().writer_id();
      rates[id].emplace_back(static_cast<std::int64_t>(m.publish_time), status.measured_rate_hz());
      late_periods[id].emplace_back(static_cast<std::int64_t>(m.publish_time),
                                    static_cast<double>(status.late_periods()));
    } else if (c.topic == "fahr/DevicePose") {
      if (!decode<msg::DevicePose, msg::DevicePosePubSubType>(m, pose)) return;
      gateway_id = pose.header().writer_id();
      const auto& f = pose.rendered_force_n();
      poses[pose.header().seq()] = {pose.header().source_time_ns(), {f.x(), f.y(), f.z()}};
      pose_times.push_back(pose.header().source_time_ns());
    } else if (c.topic == "fahr/ForceCommand") {
      if (!decode<msg::ForceCommand, msg::ForceCommandPubSubType>(m, command)) return;
      commands.push_back({command.answered_pose_seq(), command.header().source_time_ns(),
                          static_cast<std::int64_t>(m.log_time), command.header().writer_id(),
                          command.fem_step()});
    } else if (c.topic == "fahr/DeformationState") {
      if (!decode<msg::DeformationState, msg::DeformationStatePubSubType>(m, state)) return;
      states.push_back({state.header().writer_id(), state.step(), state.header().source_time_ns(),
                        state.step_s()});
    }
  });
  if (tty)
    std::fprintf(stderr, "\rfahr_trace: %llu messages read\n",
                 static_cast<unsigned long long>(report.messages));
  if (report.messages == 0) {
    std::fprintf(stderr, "fahr_trace: %s: no messages (%s)\n", path.c_str(), report.error.c_str());
    return 1;
  }
  if (!report.valid()) {
    std::fprintf(stderr, "fahr_trace: warning: %s is not a valid file (%s); using what was read\n",
                 path.c_str(), report.error.c_str());
  }
  // Every writer's stamps onto the recorder's clock (--clock).
  auto clock_of = [&](std::uint32_t writer) {
    auto it = services.find(writer);
    return clocks.of(it == services.end() ? std::string("?") : it->second.name);
  };
  auto shift_ns = [&](std::uint32_t writer) {
    const HostClock h = clock_of(writer);
    return h.error_ms < 0 ? std::int64_t{0} : static_cast<std::int64_t>(h.offset_ms * 1e6);
  };
  if (clocks.given) {
    for (auto& [id, s] : services) {
      const std::int64_t d = shift_ns(id);
      for (auto& t : s.ticks) t.start_ns -= d;
    }
    for (auto& [seq, p] : poses) p.source_ns -= shift_ns(gateway_id);
    for (auto& t : pose_times) t -= shift_ns(gateway_id);
    for (auto& c : commands) c.source_ns -= shift_ns(c.writer_id);
    for (auto& st : states) st.source_ns -= shift_ns(st.writer_id);
  }
  const std::uint32_t haptic_id = commands.empty() ? 0 : commands.back().writer_id;
  int next_pid = 1;
  std::int64_t origin = INT64_MAX;
  for (auto& [id, s] : services) {
    s.pid = next_pid++;
    std::sort(s.ticks.begin(), s.ticks.end(),
              [](const Tick& a, const Tick& b) { return a.start_ns < b.start_ns; });
    if (!s.ticks.empty()) origin = std::min(origin, s.ticks.front().start_ns);
  }
  if (!pose_times.empty()) origin = std::min(origin, pose_times.front());
  if (origin == INT64_MAX) origin = 0;

  TraceWriter trace(output);
  if (!trace.ok()) {
    std::fprintf(stderr, "fahr_trace: cannot write %s\n", output.c_str());
    return 1;
  }
  trace.origin_ns = origin;
  auto pid_of = [&](std::uint32_t writer) {
    auto it = services.find(writer);
    return it == services.end() ? 0 : it->second.pid;
  };
  // Tracks.
  for (const auto& [id, s] : services) {
    trace.raw("{\"ph\":\"M\",\"name\":\"process_name\",\"pid\":" + std::to_string(s.pid) +
              ",\"args\":{\"name\":" + quoted(s.name + " (" + std::to_string(id) + ")") + "}}");
    trace.raw("{\"ph\":\"M\",\"name\":\"thread_name\",\"pid\":" + std::to_string(s.pid) +
              ",\"tid\":1,\"args\":{\"name\":\"tick\"}}");
    trace.raw("{\"ph\":\"M\",\"name\":\"thread_name\",\"pid\":" + std::to_string(s.pid) +
              ",\"tid\":2,\"args\":{\"name\":\"samples\"}}");
    for (const auto& t : s.ticks) {
      trace.raw("{\"ph\":\"X\",\"name\":\"tick\",\"pid\":" + std::to_string(s.pid) +
                ",\"tid\":1,\"ts\":" + trace.ts(t.start_ns) +
                ",\"dur\":" + std::to_string(static_cast<double>(t.duration_ns) * 1e-3) +
                ",\"args\":{\"tick\":" + std::to_string(t.tick) +
                ",\"cpu_us\":" + std::to_string(static_cast<double>(t.cpu_ns) * 1e-3) + "}}");
    }
  }
  // The tick of a service that contains a time (or 0 if none).
  auto tick_at = [&](std::uint32_t writer, std::int64_t ns) -> const Tick* {
    auto it = services.find(writer);
    if (it == services.end()) return nullptr;
    const auto& ticks = it->second.ticks;
    auto after = std::upper_bound(ticks.begin(), ticks.end(), ns,
                                  [](std::int64_t v, const Tick& t) { return v < t.start_ns; });
    if (after == ticks.begin()) return nullptr;
    const Tick& t = *(after - 1);
    return ns <= t.start_ns + t.duration_ns ? &t : nullptr;
  };
  auto tick_after = [&](std::uint32_t writer, std::int64_t ns) -> const Tick* {
    auto it = services.find(writer);
    if (it == services.end()) return nullptr;
    const auto& ticks = it->second.ticks;
    auto after = std::upper_bound(ticks.begin(), ticks.end(), ns,
                                  [](std::int64_t v, const Tick& t) { return v < t.start_ns; });
    return after == ticks.end() ? nullptr : &*after;
  };
  // Samples, flows and motion-to-force latency.
  const int gateway_pid = pid_of(gateway_id);
  std::vector<double> motion_to_force_ms, motion_to_render_ms;
  std::size_t flows = 0;
  for (const auto& c : commands) {
    auto p = poses.find(c.pose_seq);
    if (p == poses.end()) continue;
    const double latency_ms = static_cast<double>(c.source_ns - p->second.source_ns) * 1e-6;
    motion_to_force_ms.push_back(latency_ms);
    const int haptic_pid = pid_of(c.writer_id);
    if (gateway_pid == 0 || haptic_pid == 0) continue;
    const std::string id = std::to_string(c.pose_seq);
    trace.raw("{\"ph\":\"X\",\"name\":\"DevicePose " + id +
              "\",\"pid\":" + std::to_string(gateway_pid) +
              ",\"tid\":2,\"ts\":" + trace.ts(p->second.source_ns) + ",\"dur\":1}");
    trace.raw("{\"ph\":\"s\",\"name\":\"pose\",\"cat\":\"flow\",\"id\":" + id +
              ",\"pid\":" + std::to_string(gateway_pid) +
              ",\"tid\":2,\"ts\":" + trace.ts(p->second.source_ns) + "}");
    if (const Tick* t = tick_at(c.writer_id, c.source_ns)) {
      trace.raw("{\"ph\":\"t\",\"name\":\"pose\",\"cat\":\"flow\",\"id\":" + id +
                ",\"pid\":" + std::to_string(haptic_pid) +
                ",\"tid\":1,\"ts\":" + trace.ts(std::max(t->start_ns, p->second.source_ns)) + "}");
    }
    trace.raw("{\"ph\":\"X\",\"name\":\"ForceCommand " + id + "\",\"pid\":" +
              std::to_string(haptic_pid) + ",\"tid\":2,\"ts\":" + trace.ts(c.source_ns) +
              ",\"dur\":1,\"args\":{\"motion_to_force_ms\":" + std::to_string(latency_ms) + "}}");
    trace.raw("{\"ph\":\"t\",\"name\":\"pose\",\"cat\":\"flow\",\"id\":" + id + ",\"pid\":" +
              std::to_string(haptic_pid) + ",\"tid\":2,\"ts\":" + trace.ts(c.source_ns) + "}");
    if (const Tick* servo = tick_after(gateway_id, std::max(c.log_ns, c.source_ns))) {
      trace.raw("{\"ph\":\"f\",\"bp\":\"e\",\"name\":\"pose\",\"cat\":\"flow\",\"id\":" + id +
                ",\"pid\":" + std::to_string(gateway_pid) +
                ",\"tid\":1,\"ts\":" + trace.ts(servo->start_ns) + "}");
      ++flows;
      motion_to_render_ms.push_back(static_cast<double>(servo->start_ns - p->second.source_ns) *
                                    1e-6);
    }
    trace.raw("{\"ph\":\"C\",\"name\":\"motion_to_force_ms\",\"pid\":" +
              std::to_string(haptic_pid) + ",\"ts\":" + trace.ts(c.source_ns) +
              ",\"args\":{\"ms\":" + std::to_string(latency_ms) + "}}");
  }
  for (const auto& [id, series] : rates) {
    const int pid = pid_of(id);
    if (pid == 0) continue;
    for (const auto& [ns, hz] : series) {
      trace.raw("{\"ph\":\"C\",\"name\":\"measured_rate_hz\",\"pid\":" + std::to_string(pid) +
                ",\"ts\":" + trace.ts(ns) + ",\"args\":{\"hz\":" + std::to_string(hz) + "}}");
    }
    for (const auto& [ns, late] : late_periods[id]) {
      trace.raw("{\"ph\":\"C\",\"name\":\"late_periods\",\"pid\":" + std::to_string(pid) +
                ",\"ts\":" + trace.ts(ns) + ",\"args\":{\"total\":" + std::to_string(late) + "}}");
    }
  }

  // The whole run's figures.
  std::printf("fahr_trace: %s -> %s (%zu events, %zu flows)\n", path.c_str(), output.c_str(),
              trace.count(), flows);
  const auto m2f = percentiles(motion_to_force_ms);
  const auto m2r = percentiles(motion_to_render_ms);
  std::printf("\nmotion-to-force latency over every answered DevicePose:\n");
  const double m2f_error = pair_error_ms(clock_of(gateway_id), clock_of(haptic_id));
  if (m2f_error < 0) {
    std::printf(
        "  pose written -> ForceCommand written:      not printed: the gateway's or the haptic "
        "host's clock is unknown\n");
  } else {
    std::printf(
        "  pose written -> ForceCommand written:      n %zu  p50 %.3f ms  p99 %.3f ms  "
        "p99.9 %.3f ms  max %.3f ms%s\n",
        m2f.n, m2f.p50, m2f.p99, m2f.p999, m2f.max, clock_note(m2f_error).c_str());
  }
  std::printf(
      "  pose written -> servo tick rendering it:  n %zu  p50 %.3f ms  p99 %.3f ms  "
      "p99.9 %.3f ms  max %.3f ms (approx.)\n",
      m2r.n, m2r.p50, m2r.p99, m2r.p999, m2r.max);
  print_felt(poses, commands, states, services, clocks);
  if (clocks.given) {
    std::printf(
        "\nper topic: recorder receive time - writer source time, the writer's clock corrected by "
        "its host's measured offset, +- its error (a writer of unknown clock left out)\n");
  } else {
    std::printf(
        "\nper topic: recorder receive time - writer source time (one clock: exact for writers on "
        "the recorder's host; --clock for the others)\n");
  }
  std::printf("  %-24s %9s %9s %9s %9s %9s %9s\n", "topic", "n", "p50 ms", "p99 ms", "p99.9 ms",
              "max ms", "+- ms");
  std::map<std::string, std::vector<double>> per_topic;
  std::map<std::string, double> topic_error;
  std::map<std::string, std::size_t> left_out;
  for (const auto& [key, v] : topic_latency_ms) {
    const HostClock h = clock_of(key.second);
    if (h.error_ms < 0) {
      left_out[key.first] += v.size();
      continue;
    }
    auto& out = per_topic[key.first];
    for (double x : v) out.push_back(x + h.offset_ms);
    topic_error[key.first] = std::max(topic_error[key.first], h.error_ms);
  }
  for (const auto& [topic, v] : per_topic) {
    const auto p = percentiles(v);
    std::printf("  %-24s %9zu %9.3f %9.3f %9.3f %9.3f %9.3f\n", topic.c_str(), p.n, p.p50, p.p99,
                p.p999, p.max, topic_error[topic]);
  }
  for (const auto& [topic, n] : left_out) {
    std::printf("  %-24s %9zu samples left out: their writer's clock is unknown\n", topic.c_str(),
                n);
  }
  if (pose_times.size() > 2) {
    std::vector<double> periods;
    for (std::size_t i = 1; i < pose_times.size(); ++i) {
      periods.push_back(static_cast<double>(pose_times[i] - pose_times[i - 1]) * 1e-6);
    }
    const auto p = percentiles(periods);
    std::printf(
        "\nDevicePose period (jitter): mean %.3f ms, std %.3f ms, p99 %.3f ms, max %.3f ms\n",
        p.mean, p.stddev, p.p99, p.max);
  }
  std::printf(
      "\nper service: ticks recorded, late periods (its own count), tick wall / CPU p99.9\n");
  for (const auto& [id, s] : services) {
    std::vector<double> wall, cpu;
    for (const auto& t : s.ticks) {
      wall.push_back(static_cast<double>(t.duration_ns) * 1e-3);
      cpu.push_back(static_cast<double>(t.cpu_ns) * 1e-3);
    }
    const double late = late_periods[id].empty() ? 0 : late_periods[id].back().second;
    std::printf("  %-16s ticks %8zu  late periods %6.0f  wall p99.9 %8.1f us  CPU p99.9 %8.1f us\n",
                s.name.c_str(), s.ticks.size(), late, percentiles(wall).p999,
                percentiles(cpu).p999);
  }
  for (const auto& m : report.metadata) {
    if (m.name != "fahr_recording_loss") continue;
    std::printf("\nloss per writer (sent recorded gaps drops skipped gaps-before-match):\n");
    for (const auto& [k, v] : m.values) std::printf("  %-36s %s\n", k.c_str(), v.c_str());
  }
  return 0;
}

}  // namespace
}  // namespace fahr

int main(int argc, char** argv) {
  try {
    return fahr::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_trace: %s\n", e.what());
    return 1;
  }
}
