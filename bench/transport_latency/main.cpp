// fahr_transport_latency: ping-pong round-trip times through the fahr
// transport and through each vendor's raw API, interleaved in one run, for
// a DevicePose and for 100 KB and 1 MB DeformationStates, on Fast DDS,
// Cyclone DDS and across vendors. Prints a Markdown table.
//
//   fahr_transport_latency [--round-trips N] [--large-round-trips M]
//                          [--sizes small,100k,1m] [--pairs ff,cc,fc,cf] [--markdown [FILE]]
//                          [--security-signed DIR] [--security-encrypted DIR]
//   (the pong side runs as: fahr_transport_latency --pong VENDOR DOMAIN SIZE [SECURITY_DIR])
// --security-signed / --security-encrypted: the transport path again with DDS
// Security (a station made by deployment/security/make_station_security.sh
// with --protection sign / encrypt), timed in the same interleaved blocks.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "fahr/bench_support/results_file.h"
#include "fahr/common/clock.h"
#include "ping_path.h"

namespace fahr::bench {
namespace {

using common::Vendor;
using namespace std::chrono_literals;

Payload payload_named(const std::string& name) {
  if (name == "small") return {"DevicePose (~200 B)", true, 0};
  if (name == "100k") return {"100 KB", false, 100 * std::size_t{1024}};
  if (name == "1m") return {"1 MB", false, 1024 * std::size_t{1024}};
  std::fprintf(stderr, "unknown size '%s' (small, 100k, 1m)\n", name.c_str());
  std::exit(2);
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string part; std::getline(in, part, ',');) parts.push_back(part);
  return parts;
}

int run_pong(Vendor vendor, std::uint32_t domain, const std::string& size,
             const std::string& security) {
  const Payload payload = payload_named(size);
  auto transport = make_transport_echo(vendor, domain, payload, security);
  // The raw paths are the unsecured reference only.
  std::unique_ptr<EchoPath> raw;
  if (security.empty()) {
    raw = vendor == Vendor::kFastDds ? make_raw_fast_echo(domain, payload)
                                     : make_raw_cyclone_echo(domain, payload);
  }
  // Until the parent closes our stdin (or ten minutes pass).
  char c = 0;
  while (read(STDIN_FILENO, &c, 1) > 0) {
  }
  return 0;
}

class PongProcess {
 public:
  PongProcess(Vendor vendor, std::uint32_t domain, const std::string& size,
              const std::string& security = {}) {
    int fds[2];
    if (pipe(fds) != 0) std::exit(1);
    pid_ = fork();
    if (pid_ == 0) {
      dup2(fds[0], STDIN_FILENO);
      close(fds[1]);
      const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
      const std::string v(common::vendor_name(vendor));
      const std::string d = std::to_string(domain);
      execl(self.c_str(), self.c_str(), "--pong", v.c_str(), d.c_str(), size.c_str(),
            security.c_str(), nullptr);
      _exit(127);
    }
    close(fds[0]);
    stdin_ = fds[1];
  }
  ~PongProcess() {
    close(stdin_);
    for (int i = 0; i < 200; ++i) {
      if (waitpid(pid_, nullptr, WNOHANG) == pid_) return;
      std::this_thread::sleep_for(10ms);
    }
    kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }

 private:
  int pid_ = -1;
  int stdin_ = -1;
};

struct Stats {
  std::size_t count = 0;
  double median_us = 0, p99_us = 0, p999_us = 0, max_us = 0;
};

Stats stats_of(std::vector<std::int64_t> rtt_ns) {
  Stats s;
  if (rtt_ns.empty()) return s;
  std::sort(rtt_ns.begin(), rtt_ns.end());
  auto at = [&](double q) {
    const auto i = static_cast<std::size_t>(q * static_cast<double>(rtt_ns.size() - 1));
    return static_cast<double>(rtt_ns[i]) / 1000.0;
  };
  s.count = rtt_ns.size();
  s.median_us = at(0.5);
  s.p99_us = at(0.99);
  s.p999_us = at(0.999);
  s.max_us = static_cast<double>(rtt_ns.back()) / 1000.0;
  return s;
}

// Pings until the echo comes back, so both ends have discovered each other.
bool warm_up(PingPath& path, std::uint64_t& id) {
  for (int attempt = 0; attempt < 300; ++attempt) {
    path.ping(++id);
    if (path.wait_echo(id, 100ms)) {
      for (int i = 0; i < 50; ++i) {
        path.ping(++id);
        if (!path.wait_echo(id, 2s)) return false;
      }
      return true;
    }
  }
  return false;
}

void time_block(PingPath& path, std::uint64_t& id, int n, std::vector<std::int64_t>& rtt_ns,
                int& lost) {
  for (int i = 0; i < n; ++i) {
    const std::int64_t start = common::monotonic_now_ns();
    path.ping(++id);
    if (!path.wait_echo(id, 2s)) {
      ++lost;
      continue;
    }
    rtt_ns.push_back(common::monotonic_now_ns() - start);
  }
}

void print_row(const Payload& payload, const std::string& pair, const char* path, const Stats& s,
               int lost, double ratio) {
  std::printf("| %-19s | %-21s | %-9s | %6zu | %8.1f | %8.1f | %8.1f | %9.1f | %5d |",
              payload.name.c_str(), pair.c_str(), path, s.count, s.median_us, s.p99_us, s.p999_us,
              s.max_us, lost);
  if (ratio > 0) {
    std::printf(" %5.2f |\n", ratio);
  } else {
    std::printf("       |\n");
  }
  std::fflush(stdout);
}

// A secured transport path (DDS Security with one station's files) timed
// beside the unsecured ones.
struct SecuredPath {
  std::string label;  // "signed", "encrypted"
  std::string dir;
};

int run_benchmark(int round_trips, int large_round_trips, const std::vector<std::string>& sizes,
                  const std::vector<std::string>& pairs, const std::vector<SecuredPath>& secured) {
  std::printf(
      "| payload             | ping -> pong          | path      | trips  | median us | p99 us | "
      "p99.9 us | max us | lost | transport/raw median |\n");
  std::printf("|---|---|---|---:|---:|---:|---:|---:|---:|---:|\n");
  std::uint32_t domain = 60;
  for (const auto& size : sizes) {
    const Payload payload = payload_named(size);
    const int trips = payload.small ? round_trips : large_round_trips;
    for (const auto& pair : pairs) {
      const Vendor ping_vendor = pair[0] == 'f' ? Vendor::kFastDds : Vendor::kCyclone;
      const Vendor pong_vendor = pair[1] == 'f' ? Vendor::kFastDds : Vendor::kCyclone;
      const std::string pair_name = std::string(common::vendor_name(ping_vendor)) + " -> " +
                                    std::string(common::vendor_name(pong_vendor));
      ++domain;
      PongProcess pong(pong_vendor, domain, size);
      auto transport = make_transport_ping(ping_vendor, domain, payload);
      auto raw = ping_vendor == Vendor::kFastDds ? make_raw_fast_ping(domain, payload)
                                                 : make_raw_cyclone_ping(domain, payload);
      // Each secured path on a domain of its own, with its own pong.
      std::vector<std::unique_ptr<PongProcess>> secured_pongs;
      std::vector<std::unique_ptr<PingPath>> secured_pings;
      for (const SecuredPath& s : secured) {
        ++domain;
        secured_pongs.push_back(std::make_unique<PongProcess>(pong_vendor, domain, size, s.dir));
        secured_pings.push_back(make_transport_ping(ping_vendor, domain, payload, s.dir));
      }
      std::uint64_t id = 0;
      const bool answered = warm_up(*transport, id) && warm_up(*raw, id);
      // A secured path that never answers (the vendors' handshake failed)
      // is reported and left out; the others are timed.
      std::vector<bool> secured_ok;
      for (auto& p : secured_pings) secured_ok.push_back(warm_up(*p, id));
      if (!answered) {
        std::printf("| %s | %s | no echo: pong side never answered |\n", payload.name.c_str(),
                    pair_name.c_str());
        continue;
      }
      // Interleave blocks so every path sees the same machine load.
      std::vector<std::int64_t> transport_ns, raw_ns;
      std::vector<std::vector<std::int64_t>> secured_ns(secured.size());
      std::vector<int> secured_lost(secured.size(), 0);
      int transport_lost = 0, raw_lost = 0;
      constexpr int kBlocks = 10;
      for (int b = 0; b < kBlocks; ++b) {
        time_block(*transport, id, trips / kBlocks, transport_ns, transport_lost);
        time_block(*raw, id, trips / kBlocks, raw_ns, raw_lost);
        for (std::size_t k = 0; k < secured.size(); ++k) {
          if (secured_ok[k])
            time_block(*secured_pings[k], id, trips / kBlocks, secured_ns[k], secured_lost[k]);
        }
      }
      const Stats t = stats_of(transport_ns);
      const Stats r = stats_of(raw_ns);
      print_row(payload, pair_name, "transport", t, transport_lost,
                r.median_us > 0 ? t.median_us / r.median_us : 0);
      print_row(payload, pair_name, "raw", r, raw_lost, 0);
      for (std::size_t k = 0; k < secured.size(); ++k) {
        const std::string path = "transport, " + secured[k].label;
        if (!secured_ok[k]) {
          std::printf("| %s | %s | %s | no echo: the secured participants never matched |\n",
                      payload.name.c_str(), pair_name.c_str(), path.c_str());
          continue;
        }
        const Stats s = stats_of(secured_ns[k]);
        print_row(payload, pair_name, path.c_str(), s, secured_lost[k],
                  r.median_us > 0 ? s.median_us / r.median_us : 0);
      }
    }
  }
  return 0;
}

}  // namespace
}  // namespace fahr::bench

int main(int argc, char** argv) {
  using namespace fahr;
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() >= 4 && args[0] == "--pong") {
    const auto vendor = common::resolve_vendor(args[1]);
    return bench::run_pong(vendor, static_cast<std::uint32_t>(std::stoul(args[2])), args[3],
                           args.size() > 4 ? args[4] : std::string());
  }
  bench_support::MarkdownResults results(argc, argv);
  args.assign(argv + 1, argv + argc);
  int round_trips = 10000;
  int large_round_trips = 1000;
  std::string sizes = "small,100k,1m";
  std::string pairs = "ff,cc,fc,cf";
  std::vector<bench::SecuredPath> secured;
  for (std::size_t i = 0; i + 1 < args.size(); i += 2) {
    if (args[i] == "--round-trips") {
      round_trips = std::stoi(args[i + 1]);
    } else if (args[i] == "--large-round-trips") {
      large_round_trips = std::stoi(args[i + 1]);
    } else if (args[i] == "--sizes") {
      sizes = args[i + 1];
    } else if (args[i] == "--pairs") {
      pairs = args[i + 1];
    } else if (args[i] == "--security-signed") {
      secured.push_back({"signed", args[i + 1]});
    } else if (args[i] == "--security-encrypted") {
      secured.push_back({"encrypted", args[i + 1]});
    } else {
      std::fprintf(stderr, "unknown option %s\n", args[i].c_str());
      return 2;
    }
  }
  results.begin("transport-latency");
  return bench::run_benchmark(round_trips, large_round_trips, bench::split(sizes),
                              bench::split(pairs), secured);
}
