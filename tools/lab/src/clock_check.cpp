// Clock echoes between the station supervisors (clock_check.h).
#include "clock_check.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "fahr/common/clock.h"

namespace fahr::lab {
namespace {

constexpr std::uint32_t kMagic = 0x66636c6b;  // "fclk"
constexpr int kEchoesPerRound = 20;
constexpr auto kRoundPeriod = std::chrono::seconds(2);

struct Echo {
  std::uint32_t magic = kMagic;
  std::uint32_t id = 0;
  std::int64_t t1 = 0, t2 = 0, t3 = 0;
};

int udp_socket(const std::string& address, std::uint16_t port, bool shared) {
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  const int one = 1;
  if (shared) {
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof(one));
    setsockopt(fd, SOL_SOCKET, SO_REUSEPORT, &one, sizeof(one));
  }
  sockaddr_in at{};
  at.sin_family = AF_INET;
  at.sin_port = htons(port);
  if (inet_pton(AF_INET, address.c_str(), &at.sin_addr) != 1 ||
      bind(fd, reinterpret_cast<sockaddr*>(&at), sizeof(at)) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

// `chronyc -c tracking`: this host's offset from its reference and a bound
// (|offset| + root delay / 2 + root dispersion), or empty.
std::string chrony_tracking() {
  FILE* pipe = popen("command -v chronyc >/dev/null 2>&1 && chronyc -c tracking 2>/dev/null", "r");
  if (pipe == nullptr) return "";
  char line[512] = {0};
  const bool got = std::fgets(line, sizeof line, pipe) != nullptr;
  pclose(pipe);
  if (!got) return "";
  std::vector<std::string> fields;
  std::stringstream in(line);
  for (std::string f; std::getline(in, f, ',');) fields.push_back(f);
  if (fields.size() < 12) return "";
  try {
    const double offset_s = std::stod(fields[4]);
    const double bound_s = std::fabs(offset_s) + std::stod(fields[10]) / 2 + std::stod(fields[11]);
    char text[160];
    std::snprintf(text, sizeof text, "chrony offset_ms %.3f bound_ms %.3f", offset_s * 1e3,
                  bound_s * 1e3);
    return text;
  } catch (const std::exception&) {
    return "";
  }
}

}  // namespace

ClockCheck::ClockCheck(const Plan& plan, const Station& station, const Host& self,
                       std::filesystem::path file)
    : file_(std::move(file)) {
  hosts_.push_back({self.name, self.address, 0.0, 0.0, 0});
  std::set<std::string> seen{self.name};
  for (const auto& p : plan.participants) {
    if (p.station != &station) continue;
    services_.emplace_back(service_key(p.service->kind), p.host->name);
    if (seen.insert(p.host->name).second) {
      hosts_.push_back({p.host->name, p.host->address, 0.0, -1.0, 0});
    }
  }
  if (plan.lab->clock_sync == ClockSync::kChrony) chrony_ = chrony_tracking();
  write();
  answer_fd_ = udp_socket(self.address, kClockEchoPort, true);
  if (answer_fd_ < 0) {
    std::fprintf(stderr, "fahr_lab: clock echo: cannot listen on %s:%u (%s)\n",
                 self.address.c_str(), kClockEchoPort, std::strerror(errno));
  } else {
    answer_thread_ = std::thread([this] { answer(); });
  }
  if (hosts_.size() > 1) measure_thread_ = std::thread([this] { measure(); });
}

ClockCheck::~ClockCheck() {
  stop_.store(true);
  if (answer_thread_.joinable()) answer_thread_.join();
  if (measure_thread_.joinable()) measure_thread_.join();
  if (answer_fd_ >= 0) close(answer_fd_);
}

void ClockCheck::answer() {
  while (!stop_.load()) {
    pollfd p{answer_fd_, POLLIN, 0};
    if (poll(&p, 1, 200) <= 0) continue;
    Echo e;
    sockaddr_in from{};
    socklen_t from_len = sizeof(from);
    const ssize_t got =
        recvfrom(answer_fd_, &e, sizeof(e), 0, reinterpret_cast<sockaddr*>(&from), &from_len);
    e.t2 = common::wall_now_ns();
    if (got != static_cast<ssize_t>(sizeof(e)) || e.magic != kMagic) continue;
    e.t3 = common::wall_now_ns();
    sendto(answer_fd_, &e, sizeof(e), 0, reinterpret_cast<sockaddr*>(&from), from_len);
  }
}

void ClockCheck::measure() {
  const int fd = udp_socket(hosts_[0].address, 0, false);
  if (fd < 0) return;
  std::uint32_t next_id = 1;
  auto next_round = std::chrono::steady_clock::now();
  while (!stop_.load()) {
    if (std::chrono::steady_clock::now() < next_round) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      continue;
    }
    next_round += kRoundPeriod;
    for (std::size_t h = 1; h < hosts_.size() && !stop_.load(); ++h) {
      sockaddr_in to{};
      to.sin_family = AF_INET;
      to.sin_port = htons(kClockEchoPort);
      inet_pton(AF_INET, hosts_[h].address.c_str(), &to.sin_addr);
      double best_error = -1, best_offset = 0;
      std::uint64_t answered = 0;
      for (int k = 0; k < kEchoesPerRound && !stop_.load(); ++k) {
        Echo e;
        e.id = next_id++;
        e.t1 = common::wall_now_ns();
        if (sendto(fd, &e, sizeof(e), 0, reinterpret_cast<sockaddr*>(&to), sizeof(to)) < 0) break;
        const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(100);
        while (std::chrono::steady_clock::now() < until) {
          pollfd p{fd, POLLIN, 0};
          if (poll(&p, 1, 20) <= 0) continue;
          Echo r;
          if (recv(fd, &r, sizeof(r), 0) != static_cast<ssize_t>(sizeof(r))) continue;
          const std::int64_t t4 = common::wall_now_ns();
          if (r.magic != kMagic || r.id != e.id) continue;  // a late answer to an earlier echo
          const double error_ms = static_cast<double>((t4 - r.t1) - (r.t3 - r.t2)) * 0.5e-6;
          const double offset_ms = static_cast<double>((r.t2 - r.t1) + (r.t3 - t4)) * 0.5e-6;
          ++answered;
          if (best_error < 0 || error_ms < best_error) {
            best_error = error_ms;
            best_offset = offset_ms;
          }
          break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      if (answered > 0) {
        hosts_[h].offset_ms = best_offset;
        hosts_[h].error_ms = best_error;
        hosts_[h].echoes += answered;
      }
    }
    write();
  }
  close(fd);
}

void ClockCheck::write() const {
  const auto tmp = std::filesystem::path(file_.string() + ".tmp");
  {
    std::ofstream out(tmp);
    out << "# fahr_lab clock: each host's wall clock minus this host's (" << hosts_[0].host
        << "), from the best of " << kEchoesPerRound
        << " echoes a round (error: round trip / 2); error -1: no answer yet\n";
    char line[256];
    for (const auto& h : hosts_) {
      std::snprintf(line, sizeof line, "host %s %s offset_ms %.3f error_ms %.3f echoes %llu\n",
                    h.host.c_str(), h.address.c_str(), h.offset_ms, h.error_ms,
                    static_cast<unsigned long long>(h.echoes));
      out << line;
    }
    for (const auto& [service, host] : services_)
      out << "service " << service << " " << host << "\n";
    if (!chrony_.empty()) out << chrony_ << "\n";
  }
  std::filesystem::rename(tmp, file_);
}

}  // namespace fahr::lab
