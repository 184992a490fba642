// The other process of the multi-process transport tests.
//   transport_peer echo   <vendor> <domain> <seconds>
//       republishes every sample of every topic type from fahr/test/ping/<T>
//       to fahr/test/pong/<T>, unchanged but for the writer's header stamp.
//   transport_peer writer <vendor> <domain> <period_ms> <deadline_ms> <lease_ms>
//                         <total_ms> <silent_at_ms> <silent_ms>
//       writes DevicePose on fahr/test/qos every period, silent for a while;
//       the clock starts once a reader has matched (within 20 s).
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "fahr/common/participant.h"
#include "fahr/common/publisher.h"
#include "fahr/common/subscriber.h"
#include "test_topics.h"

using namespace fahr;
using namespace fahr::common;
using std::chrono::milliseconds;

namespace {

struct EchoBase {
  virtual ~EchoBase() = default;
};

template <class T>
struct Echo final : EchoBase {
  explicit Echo(Participant& p)
      : publisher(p, test::test_qos(), test::pong_topic<T>()),
        subscriber(p, test::test_qos(), test::ping_topic<T>(),
                   [this](const T& sample, const SampleInfo&) {
                     T copy = sample;
                     publisher.write(copy);
                   }) {}
  Publisher<T> publisher;
  Subscriber<T> subscriber;
};

int run_echo(Participant& participant, int seconds) {
  std::vector<std::unique_ptr<EchoBase>> echoes;
  echoes.push_back(std::make_unique<Echo<msg::DevicePose>>(participant));
  echoes.push_back(std::make_unique<Echo<msg::ForceCommand>>(participant));
  echoes.push_back(std::make_unique<Echo<msg::ContactSet>>(participant));
  echoes.push_back(std::make_unique<Echo<msg::DeformationState>>(participant));
  echoes.push_back(std::make_unique<Echo<msg::SceneDescription>>(participant));
  echoes.push_back(std::make_unique<Echo<msg::ServiceStatus>>(participant));
  echoes.push_back(std::make_unique<Echo<msg::ServiceEvents>>(participant));
  echoes.push_back(std::make_unique<Echo<msg::SimClock>>(participant));
  echoes.push_back(std::make_unique<Echo<msg::StepAck>>(participant));
  echoes.push_back(std::make_unique<Echo<msg::GlotticView>>(participant));
  std::this_thread::sleep_for(std::chrono::seconds(seconds));
  return 0;
}

int run_writer(Participant& participant, char** argv) {
  const int period_ms = std::atoi(argv[0]);
  const int deadline_ms = std::atoi(argv[1]);
  const int lease_ms = std::atoi(argv[2]);
  const int total_ms = std::atoi(argv[3]);
  const int silent_at_ms = std::atoi(argv[4]);
  const int silent_ms = std::atoi(argv[5]);
  Publisher<msg::DevicePose> publisher(participant, test::qos_under_test(deadline_ms, lease_ms),
                                       test::kQosTopic);
  msg::DevicePose pose;
  // A starved machine can take seconds to discover the reader: the schedule
  // (and its silence) counts from the match, not from the process start.
  const auto match_by = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (publisher.matched_readers() == 0) {
    if (std::chrono::steady_clock::now() > match_by) {
      std::fprintf(stderr, "transport_peer: no reader matched within 20 s\n");
      return 3;
    }
    std::this_thread::sleep_for(milliseconds(5));
  }
  const auto start = std::chrono::steady_clock::now();
  auto next = start;
  auto last_write = start;
  bool silenced = silent_ms <= 0;
  for (int tick = 0;; ++tick) {
    next += milliseconds(period_ms);
    std::this_thread::sleep_until(next);
    const auto elapsed =
        std::chrono::duration_cast<milliseconds>(std::chrono::steady_clock::now() - start).count();
    if (elapsed >= total_ms) break;
    if (!silenced && elapsed >= silent_at_ms) {
      // The silence is measured from the last write, whenever a late wake-up
      // let it go out, so the gap between two writes is never shorter.
      silenced = true;
      std::this_thread::sleep_until(last_write + milliseconds(silent_ms));
      next = std::chrono::steady_clock::now();
    }
    pose.servo_tick(static_cast<std::uint64_t>(tick));
    last_write = std::chrono::steady_clock::now();
    publisher.write(pose);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: transport_peer echo|writer <vendor> <domain> ...\n");
    return 2;
  }
  const std::string mode = argv[1];
  TransportConfig config;
  config.vendor = resolve_vendor(argv[2]);
  config.domain_id = static_cast<std::uint32_t>(std::atoi(argv[3]));
  config.participant_name = "transport_peer";
  Participant participant(config);
  if (mode == "echo") return run_echo(participant, std::atoi(argv[4]));
  if (mode == "writer" && argc >= 10) return run_writer(participant, argv + 4);
  std::fprintf(stderr, "transport_peer: bad arguments\n");
  return 2;
}
