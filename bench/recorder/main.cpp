// fahr_bench_recorder: how fast fahr records.
//
//   fahr_bench_recorder [--writer] [--dds] [--seconds S] [--dir DIR] [--markdown [FILE]]
//
// --writer: the MCAP writer alone (fahr::mcap::Writer), 100 B, 200 B and
// 1 MiB messages, uncompressed, zstd and lz4, 1 MiB chunks, no fdatasync
// (as the MCAP C++ library's published benchmark runs), plus the recorder's
// default (zstd, fdatasync per chunk): messages/s and MiB/s of payload from
// open to the renamed, complete file.
// --dds: the recorder (fahr::logger_service::Recorder) in this process and
// a publisher in a child process over DDS, on each vendor: DevicePose at
// 1 kHz (the demo's rate), 10 kHz and as fast as the publisher can write,
// and a 256 KB DeformationState at 200 Hz; recorded against sent.
// Default: both. Run it as root inside tests/run_in_netns.sh to keep DDS
// on loopback.
#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "fahr/bench_support/results_file.h"
#include "fahr/cli/cli.h"
#include "fahr/common/clock.h"
#include "fahr/common/publisher.h"
#include "fahr/common/service_reporter.h"
#include "fahr/common/subscriber.h"
#include "fahr/logger_service/recorder.h"
#include "fahr/mcap/writer.h"

namespace fahr {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// Payloads that compress like fahr's: a pose-like record whose numbers
// drift (small), or a field of floats that varies smoothly (large).
std::vector<std::uint8_t> payload(std::size_t size, std::uint64_t i) {
  std::vector<std::uint8_t> p(size);
  std::uint64_t header[2] = {i, 1'700'000'000'000'000'000ULL + i * 1'000'000};
  std::memcpy(p.data(), header, std::min(size, sizeof(header)));
  for (std::size_t k = sizeof(header); k + 4 <= size; k += 4) {
    const float v = static_cast<float>(
        std::sin(0.001 * static_cast<double>(k) + 1e-4 * static_cast<double>(i)));
    std::memcpy(p.data() + k, &v, 4);
  }
  return p;
}

struct WriterCase {
  std::size_t size;
  std::string compression;
  bool sync;
};

void bench_writer(const std::string& dir, double seconds) {
  std::printf("## MCAP writer alone (fahr::mcap::Writer, 1 MiB chunks)\n\n");
  std::printf(
      "| message | compression | fdatasync | messages | msgs/s | MiB/s | file / payload |\n");
  std::printf("|---|---|---|---:|---:|---:|---:|\n");
  const std::vector<WriterCase> cases = {
      {100, "", false},         {200, "", false},        {200, "zstd", false},
      {200, "lz4", false},      {200, "zstd", true},     {1 << 20, "", false},
      {1 << 20, "zstd", false}, {1 << 20, "lz4", false}, {1 << 20, "zstd", true}};
  for (const auto& c : cases) {
    // Payloads made up front: the loop measures the writer only.
    std::vector<std::vector<std::uint8_t>> payloads;
    for (std::uint64_t i = 0; i < 64; ++i) payloads.push_back(payload(c.size, i));
    mcap::WriterOptions options;
    options.compression = c.compression;
    options.sync_chunks = c.sync;
    const std::string path = dir + "/bench_writer.mcap";
    std::uint64_t n = 0;
    const auto start = Clock::now();
    {
      mcap::Writer writer(options);
      writer.open(path);
      const auto schema = writer.add_schema({0, "fahr::msg::Bench", "omgidl", "struct Bench {};"});
      const auto channel = writer.add_channel({0, schema, "bench", "cdr", {}});
      // Write for `seconds`, checking the clock every 256 messages.
      const std::uint64_t t0 = 1'700'000'000'000'000'000ULL;
      while (true) {
        for (int k = 0; k < 256; ++k, ++n) {
          const auto& p = payloads[n % payloads.size()];
          writer.write_message(channel, static_cast<std::uint32_t>(n), t0 + n * 1000, t0 + n * 1000,
                               p.data(), p.size());
        }
        if (seconds_since(start) >= seconds) break;
      }
      writer.close();
    }
    const double elapsed = seconds_since(start);
    const double payload_mib = static_cast<double>(n * c.size) / (1 << 20);
    const double ratio = static_cast<double>(fs::file_size(path)) / static_cast<double>(n * c.size);
    std::printf("| %s | %s | %s | %llu | %.0f | %.1f | %.2f |\n",
                c.size >= (1 << 20) ? "1 MiB" : (std::to_string(c.size) + " B").c_str(),
                c.compression.empty() ? "none" : c.compression.c_str(), c.sync ? "yes" : "no",
                static_cast<unsigned long long>(n), static_cast<double>(n) / elapsed,
                payload_mib / elapsed, ratio);
    std::fflush(stdout);
    fs::remove(path);
  }
  std::printf("\n");
}

struct DdsCase {
  const char* what;
  double rate_hz;      // 0: as fast as the publisher can write
  std::size_t floats;  // DeformationState positions (0: DevicePose)
};

// The child: publishes for `seconds`, then its last status (sent counts).
int publish(common::Vendor vendor, std::uint32_t domain, const DdsCase& c, double seconds) {
  common::TransportConfig config;
  config.vendor = vendor;
  config.domain_id = domain;
  config.participant_name = "bench_publisher";
  common::Participant participant(config);
  common::TickRecorder ticks;
  common::ServiceReporter reporter(participant,
                                   {"bench_publisher", 1000.0, std::chrono::seconds(60)}, ticks);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // discovery
  const auto start = Clock::now();
  const auto period = std::chrono::duration<double>(c.rate_hz > 0 ? 1.0 / c.rate_hz : 0.0);
  auto next = start;
  if (c.floats == 0) {
    common::Publisher<msg::DevicePose> out(participant);
    msg::DevicePose pose;
    for (std::uint64_t i = 0; seconds_since(start) < seconds; ++i) {
      pose.servo_tick(i);
      out.write(pose);
      if (c.rate_hz > 0) {
        next += std::chrono::duration_cast<Clock::duration>(period);
        std::this_thread::sleep_until(next);
      }
    }
  } else {
    common::Publisher<msg::DeformationState> out(participant);
    msg::DeformationState state;
    state.positions_m().resize(c.floats);
    for (std::uint64_t i = 0; seconds_since(start) < seconds; ++i) {
      state.step(i);
      state.positions_m()[i % c.floats] = static_cast<float>(i);
      out.write(state);
      next += std::chrono::duration_cast<Clock::duration>(period);
      std::this_thread::sleep_until(next);
    }
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  reporter.report();
  return 0;
}

void bench_dds(const std::string& dir, double seconds, const char* self) {
  std::printf("## Recorder end to end over DDS (publisher process -> fahr_logger's Recorder)\n\n");
  std::printf(
      "| vendor | stream | rate Hz | sent | recorded | gaps | of which before match | drops | "
      "recorded MiB/s | queue peak MiB |\n");
  std::printf("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  const DdsCase cases[] = {{"DevicePose ~200 B", 1000, 0},
                           {"DevicePose ~200 B", 10000, 0},
                           {"DevicePose ~200 B", 0, 0},
                           {"DeformationState 256 KB", 200, 65536}};
  std::uint32_t domain = 60;
  for (const auto vendor : {common::Vendor::kCyclone, common::Vendor::kFastDds}) {
    for (const auto& c : cases) {
      ++domain;
      std::fflush(stdout);
      const pid_t child = fork();
      if (child == 0) {
        // A fresh process image: no DDS state shared with the parent.
        const std::string v(common::vendor_name(vendor));
        const std::string args[] = {self,
                                    "--publish",
                                    v,
                                    std::to_string(domain),
                                    std::to_string(static_cast<int>(&c - cases)),
                                    std::to_string(seconds)};
        std::vector<char*> argv;
        for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        execv(self, argv.data());
        _exit(127);
      }
      common::TransportConfig config;
      config.vendor = vendor;
      config.domain_id = domain;
      config.participant_name = "bench_recorder";
      common::Participant participant(config);
      logger_service::RecorderOptions options;
      options.path = dir + "/bench_dds.mcap";
      std::vector<logger_service::WriterTally> tallies;
      logger_service::RecorderStats stats;
      const auto start = Clock::now();
      {
        logger_service::Recorder recorder(participant, options);
        int status = 0;
        waitpid(child, &status, 0);
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        recorder.stop();
        tallies = recorder.tallies();
        stats = recorder.stats();
      }
      (void)start;
      const std::string topic = c.floats == 0 ? "fahr/DevicePose" : "fahr/DeformationState";
      for (const auto& t : tallies) {
        if (t.topic != topic) continue;
        std::printf("| %s | %s | %s | %llu | %llu | %llu | %llu | %llu | %.1f | %.1f |\n",
                    std::string(common::vendor_name(vendor)).c_str(), c.what,
                    c.rate_hz > 0 ? std::to_string(static_cast<int>(c.rate_hz)).c_str() : "max",
                    static_cast<unsigned long long>(t.sent()),
                    static_cast<unsigned long long>(t.recorded),
                    static_cast<unsigned long long>(t.total_gaps()),
                    static_cast<unsigned long long>(t.leading_gaps()),
                    static_cast<unsigned long long>(t.drops),
                    static_cast<double>(stats.bytes) / (1 << 20) / seconds,
                    static_cast<double>(stats.queue_peak_bytes) / (1 << 20));
      }
      fs::remove(options.path);
    }
  }
  std::printf("\n");
}

// The haptic tick's thread-CPU time per tick (ServiceEvents tick spans),
// split at the moment fahr_logger starts: one run, the same listener in
// both phases. The listener is a plain subscriber; the logger runs as its
// own process, started and stopped here.
struct Span {
  std::int64_t start_ns, cpu_ns, duration_ns;
};

void print_phase(const char* phase, std::vector<Span> spans) {
  if (spans.empty()) {
    std::printf("| %s | 0 | | | | | |\n", phase);
    return;
  }
  auto pct = [&](auto member, double q) {
    std::vector<std::int64_t> v;
    v.reserve(spans.size());
    for (const auto& s : spans) v.push_back(s.*member);
    std::sort(v.begin(), v.end());
    return static_cast<double>(v[static_cast<std::size_t>(q * static_cast<double>(v.size() - 1))]) *
           1e-3;
  };
  std::printf("| %s | %zu | %.1f | %.1f | %.1f | %.1f | %.1f |\n", phase, spans.size(),
              pct(&Span::cpu_ns, 0.5), pct(&Span::cpu_ns, 0.99), pct(&Span::cpu_ns, 0.999),
              pct(&Span::cpu_ns, 1.0), pct(&Span::duration_ns, 0.999));
}

pid_t start_logger(const std::string& logger, const std::string& file, const std::string& vendor,
                   std::uint32_t domain, int cpu) {
  const pid_t child = fork();
  if (child == 0) {
    if (cpu >= 0) {
      cpu_set_t set;
      CPU_ZERO(&set);
      CPU_SET(cpu, &set);
      sched_setaffinity(0, sizeof(set), &set);
    }
    const std::string args[] = {
        logger, "-o", file, "--dds", vendor, "--domain", std::to_string(domain)};
    std::vector<char*> argv;
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    // Its table would land in this bench's output: fd 1 to /dev/null (not
    // through stdout, which --markdown replaces with a copying stream).
    const int null_fd = open("/dev/null", O_WRONLY);
    if (null_fd < 0 || dup2(null_fd, STDOUT_FILENO) < 0) _exit(126);
    execv(logger.c_str(), argv.data());
    _exit(127);
  }
  return child;
}

// Stops the logger; adds the CPU time it used (user + system) to `cpu_s`.
bool stop_logger(pid_t child, double& cpu_s) {
  kill(child, SIGINT);
  int status = 0;
  struct rusage usage {};
  wait4(child, &status, 0, &usage);
  cpu_s += static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
           static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
  const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (!ok) std::fprintf(stderr, "fahr_bench_recorder: the logger ended with status %d\n", status);
  return ok;
}

int bench_overhead(const std::string& vendor, std::uint32_t domain, double seconds, double window_s,
                   const std::string& logger, const std::string& dir, int logger_cpu) {
  common::TransportConfig config;
  config.vendor = common::resolve_vendor(vendor);
  config.domain_id = domain;
  config.participant_name = "bench_overhead";
  common::Participant participant(config);
  std::mutex mutex;
  std::vector<Span> spans;
  common::Subscriber<msg::ServiceEvents> events(
      participant, common::QosProfile::for_role(common::TopicRole::kReport),
      common::TopicTraits<msg::ServiceEvents>::kName,
      [&](const msg::ServiceEvents& e, const common::SampleInfo&) {
        if (e.service_name().to_string() != "haptic") return;
        std::lock_guard lock(mutex);
        for (const auto& s : e.tick_spans())
          spans.push_back({s.start_ns(), s.cpu_ns(), s.duration_ns()});
      });
  // Windows of `window_s`, the logger off, on, off, on...: both phases
  // sample the whole scripted run alike. Each window's first second is
  // left out (the logger's start-up and discovery, or its shutdown).
  struct Window {
    std::int64_t from_ns, to_ns;
    bool logger;
  };
  std::vector<Window> windows;
  const std::string file = dir + "/bench_overhead.mcap";
  const auto start = Clock::now();
  bool ok = true;
  double logger_cpu_s = 0, logger_wall_s = 0;
  for (int i = 0; seconds_since(start) + window_s <= seconds; ++i) {
    const bool on = i % 2 == 1;
    const pid_t child = on ? start_logger(logger, file, vendor, domain, logger_cpu) : 0;
    const std::int64_t from = common::wall_now_ns() + 1'000'000'000LL;
    std::this_thread::sleep_for(std::chrono::duration<double>(window_s));
    const std::int64_t to = common::wall_now_ns();
    if (on) {
      const auto stop_start = Clock::now();
      ok = stop_logger(child, logger_cpu_s) && ok;
      logger_wall_s += window_s + seconds_since(stop_start);
    }
    windows.push_back({from, to, on});
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // the last spans arrive
  fs::remove(file);
  std::vector<Span> without, with;
  {
    std::lock_guard lock(mutex);
    for (const auto& s : spans) {
      for (const auto& w : windows) {
        if (s.start_ns >= w.from_ns && s.start_ns < w.to_ns)
          (w.logger ? with : without).push_back(s);
      }
    }
  }
  std::printf("## Haptic tick with and without fahr_logger (one run, %s)\n\n", vendor.c_str());
  std::printf(
      "The logger ran in every other %.0f s window of a %.0f s listen (%zu windows), "
      "recording every topic%s; each window's first second left out. Ticks from the haptic "
      "service's ServiceEvents tick spans.\n\n",
      window_s, seconds, windows.size(),
      logger_cpu >= 0 ? (", pinned to CPU " + std::to_string(logger_cpu)).c_str() : "");
  std::printf(
      "| phase | ticks | CPU p50 us | CPU p99 us | CPU p99.9 us | CPU max us | wall p99.9 us |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|\n");
  print_phase("without logger", without);
  print_phase("with logger", with);
  std::printf(
      "\nThe logger used %.1f s of CPU (user + system) in %.1f s of running: %.0f %% of one "
      "core.\n\n",
      logger_cpu_s, logger_wall_s, 100.0 * logger_cpu_s / std::max(logger_wall_s, 1e-9));
  return ok ? 0 : 1;
}

int run(int argc, char** argv) {
  if (argc == 6 && std::string(argv[1]) == "--publish") {
    const DdsCase cases[] = {{"", 1000, 0}, {"", 10000, 0}, {"", 0, 0}, {"", 200, 65536}};
    return publish(common::resolve_vendor(argv[2]), static_cast<std::uint32_t>(std::stoul(argv[3])),
                   cases[std::stoi(argv[4])], std::stod(argv[5]));
  }
  bench_support::MarkdownResults results(argc, argv);
  fahr::cli::App app{"fahr_bench_recorder: MCAP writer and recorder throughput"};
  bool writer = false, dds = false;
  double seconds = 3;
  std::string dir = fs::temp_directory_path().string();
  app.add_flag("--writer", writer, "the MCAP writer alone");
  app.add_flag("--dds", dds, "the recorder end to end over DDS");
  app.add_option("--seconds", seconds, "length of each case");
  app.add_option("--dir", dir, "where the files go (deleted after each case)");
  double overhead_s = 0, window_s = 5;
  std::string logger, vendor = "cyclonedds";
  std::uint32_t domain = 42;
  app.add_option("--overhead-s", overhead_s,
                 "instead: listen to a running haptic service this long, fahr_logger running "
                 "in every other window, and compare its tick CPU times in both");
  app.add_option("--window-s", window_s, "logger off/on windows of this length (default 5 s)");
  app.add_option("--logger", logger, "the fahr_logger executable (for --overhead-s)");
  app.add_option("--vendor", vendor, "DDS vendor of the running services (for --overhead-s)");
  app.add_option("--domain", domain, "their domain (for --overhead-s)");
  int logger_cpu = -1;
  app.add_option("--logger-cpu", logger_cpu, "pin the logger to this CPU (for --overhead-s)");
  app.footer(bench_support::kMarkdownHelp);
  if (const auto exit = app.parse(argc, argv)) return *exit;
  if (overhead_s > 0) {
    results.begin("recorder-overhead");
    return bench_overhead(vendor, domain, overhead_s, window_s, logger, dir, logger_cpu);
  }
  if (!writer && !dds) writer = dds = true;
  results.begin("recorder");
  if (writer) bench_writer(dir, seconds);
  if (dds) bench_dds(dir, seconds, "/proc/self/exe");
  return 0;
}

}  // namespace
}  // namespace fahr

int main(int argc, char** argv) {
  try {
    return fahr::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_bench_recorder: %s\n", e.what());
    return 1;
  }
}
