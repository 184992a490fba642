// fahr_udp_relay: the lab tests' network in user space, because this
// machine's kernel has no netem qdisc. It stands where a bridge would, in a
// namespace of its own holding the far ends of each host's veth pair, and
// switches every Ethernet frame between them itself (a learning switch on
// packet sockets): nothing crosses between hosts that it has not handled.
// Per link (a pair of ports, each direction drawn on its own), every IPv4
// UDP datagram gets a one-way delay (fixed + uniform or normal jitter,
// never below zero) and a Bernoulli loss, both from a seeded generator; the
// IP fragments of one datagram share its fate and its delay, so a 64 KB
// RTPS datagram is lost as one datagram, not as forty frames. Datagrams with
// different delays may overtake each other, as with netem's jitter. Other
// frames (ARP) get the fixed delay and are never dropped. Links not named
// pass frames at once.
//
//   fahr_udp_relay --port h1=IFACE --port h2=IFACE [--port ...]
//       [--link h1-h2:delay_ms=2,jitter_ms=1,jitter=uniform,loss=0.01]...
//       [--seed N] [--rt-priority P] [--capacity FRAMES]
//
// `A-B` sets both directions, `A>B` one. Prints "fahr_udp_relay: ready" once
// every port is open, and per direction at SIGINT/SIGTERM: frames, UDP
// datagrams, datagrams dropped, the mean delay drawn, and how late the
// frames left against their planned time (the relay's own error).
#include <arpa/inet.h>
#include <fcntl.h>
#include <linux/if_packet.h>
#include <net/ethernet.h>
#include <net/if.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <map>
#include <queue>
#include <random>
#include <string>
#include <vector>

#include "fahr/cli/cli.h"
#include "fahr/metrics/duration_histogram.h"

namespace fahr::lab_relay {
namespace {

constexpr std::size_t kFrameBytes = 2048;  // a 1,500-byte MTU frame and its header
constexpr std::size_t kFateSlots = 4096;   // fragmented datagrams in flight, per relay

std::atomic<bool> g_stop{false};
void on_signal(int) {
  g_stop.store(true);
}

double ms(std::chrono::nanoseconds d) {
  return static_cast<double>(d.count()) * 1e-6;
}

std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

struct LinkModel {
  double delay_ms = 0;
  double jitter_ms = 0;
  bool normal = false;  // jitter: uniform in [-j, j] or normal with sd j
  double loss = 0;
};

// One direction of one link: its model, generator and books.
struct Direction {
  LinkModel model;
  std::mt19937_64 rng;
  std::uint64_t frames = 0, datagrams = 0, dropped = 0, sent = 0;
  double delay_sum_ms = 0;
  metrics::DurationHistogram late{std::chrono::microseconds(10)};

  // A datagram's delay, ns, and whether it is lost.
  std::pair<std::int64_t, bool> draw() {
    double d = model.delay_ms;
    if (model.jitter_ms > 0) {
      if (model.normal) {
        d += std::normal_distribution<double>(0.0, model.jitter_ms)(rng);
      } else {
        d += std::uniform_real_distribution<double>(-model.jitter_ms, model.jitter_ms)(rng);
      }
    }
    d = std::max(d, 0.0);
    const bool lost =
        model.loss > 0 && std::uniform_real_distribution<double>(0.0, 1.0)(rng) < model.loss;
    return {static_cast<std::int64_t>(d * 1e6), lost};
  }
};

// What was drawn for a fragmented datagram, looked up by its later fragments.
struct Fate {
  std::uint32_t src = 0, dst = 0;
  std::uint16_t id = 0;
  int direction = -1;
  std::int64_t delay_ns = 0;
  bool lost = false;
};

struct Port {
  std::string name, interface;
  int fd = -1;
  std::array<std::uint8_t, 6> mac{};
};

struct Queued {
  std::int64_t release_ns;
  std::uint64_t order;
  std::uint32_t slot;
  bool operator>(const Queued& o) const {
    return release_ns != o.release_ns ? release_ns > o.release_ns : order > o.order;
  }
};

std::uint16_t fold(std::uint32_t sum) {
  while (sum >> 16) sum = (sum & 0xffff) + (sum >> 16);
  return static_cast<std::uint16_t>(sum);
}

std::uint32_t add_bytes(std::uint32_t sum, const std::uint8_t* p, std::size_t n) {
  for (std::size_t i = 0; i + 1 < n; i += 2)
    sum += static_cast<std::uint32_t>(p[i] << 8 | p[i + 1]);
  if (n % 2 == 1) sum += static_cast<std::uint32_t>(p[n - 1] << 8);
  return sum;
}

// A frame a local sender left with its UDP or TCP checksum to the device
// (veth offload, TP_STATUS_CSUMNOTREADY): the relay fills it in, since the
// receiving host will check it.
void complete_checksum(std::uint8_t* frame, std::size_t len) {
  if (len < 34 || frame[12] != 0x08 || frame[13] != 0x00) return;
  std::uint8_t* ip = frame + 14;
  const std::size_t ihl = static_cast<std::size_t>(ip[0] & 0x0f) * 4;
  const std::size_t total = static_cast<std::size_t>(ip[2] << 8 | ip[3]);
  if (ihl < 20 || 14 + total > len || total <= ihl) return;
  const std::uint8_t proto = ip[9];
  std::uint8_t* l4 = ip + ihl;
  const std::size_t l4_len = total - ihl;
  std::size_t at = 0;
  if (proto == 17 && l4_len >= 8) {
    at = 6;
  } else if (proto == 6 && l4_len >= 20) {
    at = 16;
  } else {
    return;
  }
  l4[at] = 0;
  l4[at + 1] = 0;
  std::uint32_t sum = add_bytes(0, ip + 12, 8);  // source and destination address
  sum += proto;
  sum += static_cast<std::uint32_t>(l4_len);
  sum = add_bytes(sum, l4, l4_len);
  std::uint16_t c = static_cast<std::uint16_t>(~fold(sum));
  if (c == 0 && proto == 17) c = 0xffff;
  l4[at] = static_cast<std::uint8_t>(c >> 8);
  l4[at + 1] = static_cast<std::uint8_t>(c & 0xff);
}

int open_port(Port& port) {
  const unsigned index = if_nametoindex(port.interface.c_str());
  if (index == 0) {
    std::fprintf(stderr, "fahr_udp_relay: no interface '%s'\n", port.interface.c_str());
    return -1;
  }
  const int fd = socket(AF_PACKET, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, htons(ETH_P_ALL));
  if (fd < 0) {
    std::fprintf(stderr, "fahr_udp_relay: packet socket: %s (needs CAP_NET_RAW)\n",
                 std::strerror(errno));
    return -1;
  }
  sockaddr_ll addr{};
  addr.sll_family = AF_PACKET;
  addr.sll_protocol = htons(ETH_P_ALL);
  addr.sll_ifindex = static_cast<int>(index);
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
    std::fprintf(stderr, "fahr_udp_relay: bind %s: %s\n", port.interface.c_str(),
                 std::strerror(errno));
    close(fd);
    return -1;
  }
  packet_mreq promisc{};
  promisc.mr_ifindex = static_cast<int>(index);
  promisc.mr_type = PACKET_MR_PROMISC;
  const int one = 1;
  const int buffer = 8 << 20;
  if (setsockopt(fd, SOL_PACKET, PACKET_ADD_MEMBERSHIP, &promisc, sizeof(promisc)) != 0 ||
      setsockopt(fd, SOL_PACKET, PACKET_AUXDATA, &one, sizeof(one)) != 0) {
    std::fprintf(stderr, "fahr_udp_relay: %s: %s\n", port.interface.c_str(), std::strerror(errno));
    close(fd);
    return -1;
  }
  // Its own frames are not input (older kernels: skipped by packet type below).
  (void)setsockopt(fd, SOL_PACKET, PACKET_IGNORE_OUTGOING, &one, sizeof(one));
  if (setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &buffer, sizeof(buffer)) != 0)
    (void)setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &buffer, sizeof(buffer));
  if (setsockopt(fd, SOL_SOCKET, SO_SNDBUFFORCE, &buffer, sizeof(buffer)) != 0)
    (void)setsockopt(fd, SOL_SOCKET, SO_SNDBUF, &buffer, sizeof(buffer));
  port.fd = fd;
  return 0;
}

bool parse_model(const std::string& text, LinkModel& m, std::string& error) {
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t end = std::min(text.find(',', at), text.size());
    const std::string item = text.substr(at, end - at);
    at = end + 1;
    const std::size_t eq = item.find('=');
    if (eq == std::string::npos) {
      error = "'" + item + "' is not key=value";
      return false;
    }
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    try {
      if (key == "delay_ms") {
        m.delay_ms = std::stod(value);
      } else if (key == "jitter_ms") {
        m.jitter_ms = std::stod(value);
      } else if (key == "loss") {
        m.loss = std::stod(value);
      } else if (key == "jitter") {
        if (value != "uniform" && value != "normal") {
          error = "jitter is uniform or normal";
          return false;
        }
        m.normal = value == "normal";
      } else {
        error = "unknown key '" + key + "' (delay_ms, jitter_ms, jitter, loss)";
        return false;
      }
    } catch (const std::exception&) {
      error = "'" + value + "' is not a number";
      return false;
    }
  }
  if (!(m.delay_ms >= 0 && m.delay_ms <= 1000 && m.jitter_ms >= 0 && m.jitter_ms <= 1000 &&
        m.loss >= 0 && m.loss <= 1)) {
    error = "delay_ms and jitter_ms in [0, 1000], loss in [0, 1]";
    return false;
  }
  return true;
}

int run(int argc, char** argv) {
  fahr::cli::App app{"fahr_udp_relay: a switch between network namespaces that delays and drops"};
  std::vector<std::string> port_specs, link_specs;
  std::uint64_t seed = 1;
  int rt_priority = 0;
  std::uint32_t capacity = 16384;
  app.add_option("--port", port_specs, "NAME=INTERFACE, one per host")->required();
  app.add_option("--link", link_specs,
                 "A-B:delay_ms=..,jitter_ms=..,jitter=uniform|normal,loss=..");
  app.add_option("--seed", seed, "seed of every link's generator");
  app.add_option("--rt-priority", rt_priority, "SCHED_FIFO priority (0: none)")
      ->check(fahr::cli::Range(0, 99));
  app.add_option("--capacity", capacity, "frames held at once")
      ->check(fahr::cli::Range(64, 1 << 20));
  if (const auto exit = app.parse(argc, argv)) return *exit;

  std::vector<Port> ports;
  std::map<std::string, int> by_name;
  for (const auto& spec : port_specs) {
    const std::size_t eq = spec.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size()) {
      std::fprintf(stderr, "fahr_udp_relay: --port %s: expected NAME=INTERFACE\n", spec.c_str());
      return 2;
    }
    Port p;
    p.name = spec.substr(0, eq);
    p.interface = spec.substr(eq + 1);
    if (by_name.count(p.name) != 0) {
      std::fprintf(stderr, "fahr_udp_relay: port %s given twice\n", p.name.c_str());
      return 2;
    }
    by_name[p.name] = static_cast<int>(ports.size());
    ports.push_back(p);
  }
  const std::size_t n = ports.size();
  std::vector<Direction> directions(n * n);
  for (std::size_t i = 0; i < directions.size(); ++i) {
    directions[i].rng.seed(seed * 1000003u + i);
  }
  std::vector<bool> named(n * n, false);
  for (const auto& spec : link_specs) {
    const std::size_t colon = spec.find(':');
    const std::string pair = spec.substr(0, colon);
    const std::size_t sep = pair.find_first_of("->");
    if (colon == std::string::npos || sep == std::string::npos) {
      std::fprintf(stderr, "fahr_udp_relay: --link %s: expected A-B:... or A>B:...\n",
                   spec.c_str());
      return 2;
    }
    const std::string a = pair.substr(0, sep), b = pair.substr(sep + 1);
    if (by_name.count(a) == 0 || by_name.count(b) == 0 || a == b) {
      std::fprintf(stderr, "fahr_udp_relay: --link %s: two different ports\n", spec.c_str());
      return 2;
    }
    LinkModel m;
    std::string error;
    if (!parse_model(spec.substr(colon + 1), m, error)) {
      std::fprintf(stderr, "fahr_udp_relay: --link %s: %s\n", spec.c_str(), error.c_str());
      return 2;
    }
    const auto ia = static_cast<std::size_t>(by_name[a]), ib = static_cast<std::size_t>(by_name[b]);
    directions[ia * n + ib].model = m;
    named[ia * n + ib] = true;
    if (pair[sep] == '-') {
      directions[ib * n + ia].model = m;
      named[ib * n + ia] = true;
    }
  }
  for (auto& p : ports) {
    if (open_port(p) != 0) return 1;
  }

  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
  prctl(PR_SET_TIMERSLACK, 1UL);
  if (rt_priority > 0) {
    sched_param param{};
    param.sched_priority = rt_priority;
    if (sched_setscheduler(0, SCHED_FIFO, &param) != 0) {
      std::fprintf(stderr, "fahr_udp_relay: SCHED_FIFO %d: %s; running without\n", rt_priority,
                   std::strerror(errno));
    }
  }

  // Everything the loop uses, allocated once.
  std::vector<std::uint8_t> pool(static_cast<std::size_t>(capacity) * kFrameBytes);
  std::vector<std::uint32_t> lengths(capacity, 0);
  std::vector<std::uint16_t> egress(capacity, 0), ingress(capacity, 0);
  std::vector<std::uint32_t> free_slots(capacity);
  for (std::uint32_t i = 0; i < capacity; ++i) free_slots[i] = capacity - 1 - i;
  std::vector<Queued> heap_storage;
  heap_storage.reserve(capacity);
  std::priority_queue<Queued, std::vector<Queued>, std::greater<>> queue(std::greater<>{},
                                                                         std::move(heap_storage));
  std::vector<Fate> fates(kFateSlots);
  std::map<std::array<std::uint8_t, 6>, int> learned;  // source MAC -> port (a few hosts)
  std::vector<pollfd> polls(n);
  for (std::size_t i = 0; i < n; ++i) polls[i] = {ports[i].fd, POLLIN, 0};
  std::uint64_t order = 0, overflow = 0, truncated = 0, send_errors = 0, checksums = 0;
  std::vector<int> targets;
  targets.reserve(n);

  std::printf("fahr_udp_relay: ready: %zu ports", n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      if (!named[i * n + j]) continue;
      const auto& m = directions[i * n + j].model;
      std::printf(", %s>%s delay %.3f ms jitter %.3f ms (%s) loss %.4f", ports[i].name.c_str(),
                  ports[j].name.c_str(), m.delay_ms, m.jitter_ms, m.normal ? "normal" : "uniform",
                  m.loss);
    }
  }
  std::printf("\n");
  std::fflush(stdout);

  std::array<std::uint8_t, kFrameBytes> scratch{};
  while (!g_stop.load()) {
    // Frames whose time has come.
    std::int64_t now = now_ns();
    while (!queue.empty() && queue.top().release_ns <= now) {
      const Queued q = queue.top();
      queue.pop();
      const int out = egress[q.slot];
      const std::uint8_t* frame = pool.data() + static_cast<std::size_t>(q.slot) * kFrameBytes;
      if (send(ports[static_cast<std::size_t>(out)].fd, frame, lengths[q.slot], 0) < 0) {
        ++send_errors;
      }
      free_slots.push_back(q.slot);
      directions[ingress[q.slot] * n + static_cast<std::size_t>(out)].late.record(
          std::chrono::nanoseconds(now - q.release_ns));
      now = now_ns();
    }
    timespec timeout{0, 100'000'000};
    if (!queue.empty()) {
      const std::int64_t wait = std::max<std::int64_t>(queue.top().release_ns - now, 0);
      timeout = {static_cast<time_t>(wait / 1'000'000'000),
                 static_cast<long>(wait % 1'000'000'000)};
    }
    const int ready = ppoll(polls.data(), n, &timeout, nullptr);
    if (ready < 0) {
      if (errno == EINTR) continue;
      std::fprintf(stderr, "fahr_udp_relay: poll: %s\n", std::strerror(errno));
      return 1;
    }
    if (ready == 0) continue;
    for (std::size_t in = 0; in < n; ++in) {
      if ((polls[in].revents & POLLIN) == 0) continue;
      for (int batch = 0; batch < 256; ++batch) {
        std::uint8_t* buffer = scratch.data();
        sockaddr_ll from{};
        iovec iov{buffer, kFrameBytes};
        alignas(cmsghdr) std::array<std::uint8_t, CMSG_SPACE(sizeof(tpacket_auxdata))> control{};
        msghdr msg{};
        msg.msg_name = &from;
        msg.msg_namelen = sizeof(from);
        msg.msg_iov = &iov;
        msg.msg_iovlen = 1;
        msg.msg_control = control.data();
        msg.msg_controllen = control.size();
        const ssize_t got = recvmsg(ports[in].fd, &msg, MSG_TRUNC);
        if (got < 0) break;  // EAGAIN: drained
        if (from.sll_pkttype == PACKET_OUTGOING) continue;
        const std::int64_t arrived = now_ns();
        if (static_cast<std::size_t>(got) > kFrameBytes || got < 14) {
          ++truncated;
          continue;
        }
        const auto len = static_cast<std::size_t>(got);
        for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
          if (c->cmsg_level != SOL_PACKET || c->cmsg_type != PACKET_AUXDATA) continue;
          tpacket_auxdata aux{};
          std::memcpy(&aux, CMSG_DATA(c), sizeof(aux));
          if ((aux.tp_status & TP_STATUS_CSUMNOTREADY) != 0) {
            complete_checksum(buffer, len);
            ++checksums;
          }
        }
        // Switch: learn the sender, look up the receiver (flood if unknown).
        std::array<std::uint8_t, 6> dst{}, src{};
        std::memcpy(dst.data(), buffer, 6);
        std::memcpy(src.data(), buffer + 6, 6);
        if (learned.size() < 1024 || learned.count(src) != 0) learned[src] = static_cast<int>(in);
        targets.clear();
        const auto hit = (dst[0] & 1) == 0 ? learned.find(dst) : learned.end();
        if (hit != learned.end()) {
          if (hit->second != static_cast<int>(in)) targets.push_back(hit->second);
        } else {
          for (std::size_t o = 0; o < n; ++o)
            if (o != in) targets.push_back(static_cast<int>(o));
        }
        // An IPv4 UDP datagram (or a fragment of one) is impaired.
        const bool udp = len >= 34 && buffer[12] == 0x08 && buffer[13] == 0x00 && buffer[23] == 17;
        bool fragment = false;
        std::uint32_t ip_src = 0, ip_dst = 0;
        std::uint16_t ip_id = 0;
        bool first_piece = true;
        if (udp) {
          const std::uint16_t frag = static_cast<std::uint16_t>(buffer[20] << 8 | buffer[21]);
          fragment = (frag & 0x2000) != 0 || (frag & 0x1fff) != 0;
          first_piece = (frag & 0x1fff) == 0;
          std::memcpy(&ip_src, buffer + 26, 4);
          std::memcpy(&ip_dst, buffer + 30, 4);
          ip_id = static_cast<std::uint16_t>(buffer[18] << 8 | buffer[19]);
        }
        for (const int out : targets) {
          Direction& d = directions[in * n + static_cast<std::size_t>(out)];
          ++d.frames;
          std::int64_t delay_ns = static_cast<std::int64_t>(d.model.delay_ms * 1e6);
          bool lost = false;
          if (udp) {
            const int dir = static_cast<int>(in * n + static_cast<std::size_t>(out));
            Fate* fate = nullptr;
            if (fragment) {
              const std::size_t h = (ip_src * 2654435761u ^ ip_dst * 40503u ^ ip_id * 97u ^
                                     static_cast<std::uint32_t>(dir) * 131u) %
                                    kFateSlots;
              fate = &fates[h];
              const bool known = fate->direction == dir && fate->src == ip_src &&
                                 fate->dst == ip_dst && fate->id == ip_id;
              if (known && !first_piece) {
                delay_ns = fate->delay_ns;
                lost = fate->lost;
                fate = nullptr;
              }
            }
            if (!fragment || fate != nullptr) {
              std::tie(delay_ns, lost) = d.draw();
              ++d.datagrams;
              if (lost) ++d.dropped;
              d.delay_sum_ms += static_cast<double>(delay_ns) * 1e-6;
              if (fate != nullptr) *fate = {ip_src, ip_dst, ip_id, dir, delay_ns, lost};
            }
          }
          if (lost) continue;
          if (free_slots.empty()) {
            ++overflow;
            continue;
          }
          const std::uint32_t slot = free_slots.back();
          free_slots.pop_back();
          std::memcpy(pool.data() + static_cast<std::size_t>(slot) * kFrameBytes, buffer, len);
          lengths[slot] = static_cast<std::uint32_t>(len);
          egress[slot] = static_cast<std::uint16_t>(out);
          ingress[slot] = static_cast<std::uint16_t>(in);
          queue.push({arrived + delay_ns, order++, slot});
          ++d.sent;
        }
      }
    }
  }

  // The books.
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  const double cpu_s = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                       static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      const Direction& d = directions[i * n + j];
      if (d.frames == 0) continue;
      std::printf(
          "fahr_udp_relay: %s>%s: frames %llu, UDP datagrams %llu, dropped %llu (%.2f %%), "
          "mean delay drawn %.3f ms, left late p50 %.3f ms p99 %.3f ms max %.3f ms\n",
          ports[i].name.c_str(), ports[j].name.c_str(), static_cast<unsigned long long>(d.frames),
          static_cast<unsigned long long>(d.datagrams), static_cast<unsigned long long>(d.dropped),
          d.datagrams > 0
              ? 100.0 * static_cast<double>(d.dropped) / static_cast<double>(d.datagrams)
              : 0.0,
          d.datagrams > 0 ? d.delay_sum_ms / static_cast<double>(d.datagrams) : 0.0,
          ms(d.late.percentile(0.5)), ms(d.late.percentile(0.99)), ms(d.late.max()));
    }
  }
  std::printf(
      "fahr_udp_relay: checksums completed %llu, frames refused (pool full) %llu, oversized %llu, "
      "send errors %llu, CPU %.2f s\n",
      static_cast<unsigned long long>(checksums), static_cast<unsigned long long>(overflow),
      static_cast<unsigned long long>(truncated), static_cast<unsigned long long>(send_errors),
      cpu_s);
  return 0;
}

}  // namespace
}  // namespace fahr::lab_relay

int main(int argc, char** argv) {
  try {
    return fahr::lab_relay::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_udp_relay: %s\n", e.what());
    return 1;
  }
}
