// fahr_udp_probe: measures a path between two network namespaces of one
// machine (they share its clocks): the sender stamps each datagram with its
// sequence number and CLOCK_REALTIME, the receiver takes the kernel's
// receive time (SO_TIMESTAMPNS) and prints the one-way delays and the loss.
// Used by tests/lab/udp_relay.sh to check fahr_udp_relay.
//
//   fahr_udp_probe send ADDRESS PORT --count N --rate-hz R --size BYTES
//   fahr_udp_probe receive PORT --count N --size BYTES [--timeout-s T]
//
// The receiver ends when the last datagram has come or T seconds passed
// without one (after the first) and prints one line of key=value figures.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>
#include <vector>

#include "fahr/cli/cli.h"

namespace fahr::lab_probe {
namespace {

constexpr std::uint32_t kMagic = 0x66616872;  // "fahr"

struct Stamp {
  std::uint32_t magic;
  std::uint32_t size;
  std::uint64_t seq;
  std::int64_t sent_ns;
};

std::int64_t realtime_ns() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

int send_probe(const std::string& address, int port, std::uint64_t count, double rate_hz,
               std::size_t size) {
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  if (fd < 0 || inet_pton(AF_INET, address.c_str(), &to.sin_addr) != 1) {
    std::fprintf(stderr, "fahr_udp_probe: cannot send to %s\n", address.c_str());
    return 1;
  }
  std::vector<std::uint8_t> payload(std::max(size, sizeof(Stamp)), 0x5a);
  const std::int64_t period_ns = static_cast<std::int64_t>(1e9 / rate_hz);
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  std::uint64_t failed = 0;
  for (std::uint64_t i = 0; i < count; ++i) {
    Stamp s{kMagic, static_cast<std::uint32_t>(payload.size()), i, realtime_ns()};
    std::memcpy(payload.data(), &s, sizeof(s));
    if (sendto(fd, payload.data(), payload.size(), 0, reinterpret_cast<sockaddr*>(&to),
               sizeof(to)) < 0)
      ++failed;
    next.tv_nsec += period_ns;
    while (next.tv_nsec >= 1'000'000'000) {
      next.tv_nsec -= 1'000'000'000;
      ++next.tv_sec;
    }
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
  }
  std::printf("fahr_udp_probe: sent=%llu send_errors=%llu\n",
              static_cast<unsigned long long>(count), static_cast<unsigned long long>(failed));
  close(fd);
  return failed == 0 ? 0 : 1;
}

int receive_probe(int port, std::uint64_t count, std::size_t size, double timeout_s) {
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  const int one = 1, buffer = 8 << 20;
  setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &one, sizeof(one));
  if (setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &buffer, sizeof(buffer)) != 0)
    setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &buffer, sizeof(buffer));
  sockaddr_in at{};
  at.sin_family = AF_INET;
  at.sin_port = htons(static_cast<std::uint16_t>(port));
  at.sin_addr.s_addr = htonl(INADDR_ANY);
  if (fd < 0 || bind(fd, reinterpret_cast<sockaddr*>(&at), sizeof(at)) != 0) {
    std::fprintf(stderr, "fahr_udp_probe: bind %d: %s\n", port, std::strerror(errno));
    return 1;
  }
  std::printf("fahr_udp_probe: listening on %d\n", port);
  std::fflush(stdout);
  std::vector<std::uint8_t> data(std::max<std::size_t>(size, 65536));
  std::vector<double> delays_ms;
  std::vector<bool> seen(count, false);
  std::uint64_t received = 0, duplicates = 0, reordered = 0, foreign = 0, wrong_size = 0;
  std::uint64_t highest = 0;
  bool first = true;
  // Before the first datagram: wait up to 30 s (the sender starts later).
  while (received < count) {
    pollfd p{fd, POLLIN, 0};
    const int wait_ms = static_cast<int>((first ? 30.0 : timeout_s) * 1000.0);
    const int ready = poll(&p, 1, wait_ms);
    if (ready <= 0) break;
    char control[CMSG_SPACE(sizeof(timespec))];
    iovec iov{data.data(), data.size()};
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control;
    msg.msg_controllen = sizeof(control);
    const ssize_t got = recvmsg(fd, &msg, 0);
    if (got < static_cast<ssize_t>(sizeof(Stamp))) continue;
    std::int64_t rx_ns = realtime_ns();
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_TIMESTAMPNS) {
        timespec ts{};
        std::memcpy(&ts, CMSG_DATA(c), sizeof(ts));
        rx_ns = static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
      }
    }
    Stamp s{};
    std::memcpy(&s, data.data(), sizeof(s));
    if (s.magic != kMagic || s.seq >= count) {
      ++foreign;
      continue;
    }
    if (static_cast<std::size_t>(got) != s.size) ++wrong_size;
    first = false;
    if (seen[s.seq]) {
      ++duplicates;
      continue;
    }
    seen[s.seq] = true;
    ++received;
    if (s.seq < highest) ++reordered;
    highest = std::max(highest, s.seq);
    delays_ms.push_back(static_cast<double>(rx_ns - s.sent_ns) * 1e-6);
  }
  std::sort(delays_ms.begin(), delays_ms.end());
  auto at_q = [&](double q) {
    if (delays_ms.empty()) return 0.0;
    return delays_ms[static_cast<std::size_t>(q * static_cast<double>(delays_ms.size() - 1))];
  };
  double mean = 0;
  for (double d : delays_ms) mean += d;
  if (!delays_ms.empty()) mean /= static_cast<double>(delays_ms.size());
  std::printf(
      "fahr_udp_probe: expected=%llu received=%llu lost=%llu duplicates=%llu reordered=%llu "
      "foreign=%llu wrong_size=%llu delay_min_ms=%.3f delay_p05_ms=%.3f delay_p50_ms=%.3f "
      "delay_mean_ms=%.3f delay_p95_ms=%.3f delay_p99_ms=%.3f delay_max_ms=%.3f\n",
      static_cast<unsigned long long>(count), static_cast<unsigned long long>(received),
      static_cast<unsigned long long>(count - received),
      static_cast<unsigned long long>(duplicates), static_cast<unsigned long long>(reordered),
      static_cast<unsigned long long>(foreign), static_cast<unsigned long long>(wrong_size),
      delays_ms.empty() ? 0.0 : delays_ms.front(), at_q(0.05), at_q(0.5), mean, at_q(0.95),
      at_q(0.99), delays_ms.empty() ? 0.0 : delays_ms.back());
  close(fd);
  return received > 0 ? 0 : 1;
}

int run(int argc, char** argv) {
  fahr::cli::App app{"fahr_udp_probe: one-way delay and loss between two namespaces"};
  app.require_subcommand(1);
  std::string address;
  int port = 0;
  std::uint64_t count = 1000;
  double rate_hz = 1000, timeout_s = 2;
  std::size_t size = 200;
  auto* send = app.add_subcommand("send", "send stamped datagrams");
  send->add_option("address", address, "IPv4 address")->required();
  send->add_option("port", port, "UDP port")->required()->check(fahr::cli::Range(1, 65535));
  send->add_option("--count", count, "datagrams");
  send->add_option("--rate-hz", rate_hz, "datagrams a second")->check(fahr::cli::Range(1.0, 1e5));
  send->add_option("--size", size, "bytes each")->check(fahr::cli::Range(24, 65000));
  auto* receive = app.add_subcommand("receive", "receive and measure");
  receive->add_option("port", port, "UDP port")->required()->check(fahr::cli::Range(1, 65535));
  receive->add_option("--count", count, "datagrams expected");
  receive->add_option("--size", size, "bytes each")->check(fahr::cli::Range(24, 65000));
  receive->add_option("--timeout-s", timeout_s, "end after this long without a datagram");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  if (send->parsed()) return send_probe(address, port, count, rate_hz, size);
  return receive_probe(port, count, size, timeout_s);
}

}  // namespace
}  // namespace fahr::lab_probe

int main(int argc, char** argv) {
  try {
    return fahr::lab_probe::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_udp_probe: %s\n", e.what());
    return 1;
  }
}
