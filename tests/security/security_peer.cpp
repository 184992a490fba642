// security_peer: one participant of the DDS Security tests, with the identity
// it is given (or none).
//
//   security_peer listen  --seconds S [--dds V] [--domain N] [--security DIR] [--identity NAME]
//   security_peer command --seconds S [...]
//
// listen: counts the ForceCommands it receives, by writer, and prints
//   "listen: received N ForceCommand from W writers: <writer>=<n> ...".
// command: publishes a well-formed ForceCommand every millisecond answering
//   the newest DevicePose it sees (zero until the gateway is enabled, then
//   2 N upward, no stiffness: what a hostile participant would send), and
//   prints "command: writer <id> wrote N, matched readers M" — or
//   "command: refused: <why>" when its participant or writer is not allowed
//   to exist.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "fahr/cli/cli.h"
#include "fahr/common/publisher.h"
#include "fahr/common/subscriber.h"

int main(int argc, char** argv) {
  using namespace fahr;
  fahr::cli::App app{"a participant of the DDS Security tests"};
  std::string mode, dds, domain, security, identity;
  double seconds = 5;
  app.add_option("mode", mode, "listen or command")
      ->required()
      ->check(fahr::cli::IsMember({"listen", "command"}));
  app.add_option("--seconds", seconds, "how long");
  app.add_option("--dds", dds, "DDS vendor");
  app.add_option("--domain", domain, "DDS domain id");
  app.add_option("--security", security, "the station's security folder");
  app.add_option("--identity", identity, "identity in that folder (default: the mode's name)");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  try {
    if (!identity.empty()) setenv("FAHR_DDS_IDENTITY", identity.c_str(), 1);
    const auto config = common::transport_config_from(dds, domain, "", "security_peer", security);
    common::Participant participant(config);
    if (mode == "listen") {
      std::mutex mutex;
      std::map<std::uint32_t, std::uint64_t> by_writer;
      std::uint64_t total = 0;
      common::Subscriber<msg::ForceCommand> commands(
          participant, common::QosProfile::for_role(common::TopicRole::kServoStream),
          common::TopicTraits<msg::ForceCommand>::kName,
          [&](const msg::ForceCommand& c, const common::SampleInfo&) {
            std::lock_guard lock(mutex);
            ++by_writer[c.header().writer_id()];
            ++total;
          });
      std::printf("listen: ready\n");
      while (std::chrono::steady_clock::now() < end)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      std::lock_guard lock(mutex);
      std::printf("listen: received %llu ForceCommand from %zu writers:",
                  static_cast<unsigned long long>(total), by_writer.size());
      for (const auto& [writer, n] : by_writer)
        std::printf(" %u=%llu", writer, static_cast<unsigned long long>(n));
      std::printf("\n");
      return 0;
    }
    common::Subscriber<msg::DevicePose> poses(participant);
    std::unique_ptr<common::Publisher<msg::ForceCommand>> out;
    try {
      out = std::make_unique<common::Publisher<msg::ForceCommand>>(participant);
    } catch (const std::exception& e) {
      std::printf("command: refused: %s\n", e.what());
      return 0;
    }
    msg::ForceCommand command;
    command.device_id(1);
    std::uint64_t wrote = 0;
    // What a hostile participant that knows the gateway's rules sends: zero
    // until the gateway says it is enabled (its engage rule wants 50 ticks
    // of a small force), then 2 N; zero again whenever it drops the force (a
    // starved machine's silences), to engage again. Following the state the
    // poses carry, not a clock, keeps it from pushing while the gateway
    // engages however late its own wake-ups come.
    while (std::chrono::steady_clock::now() < end) {
      if (poses.fetch_newest()) {
        const msg::DevicePose& pose = poses.newest();
        command.answered_pose_seq(pose.header().seq());
        command.answered_position_m(pose.world_from_stylus().position_m());
        command.force_n().y(pose.safety_state() == msg::DEVICE_FORCE_ENABLED ? 2.0 : 0.0);
      }
      if (command.answered_pose_seq() == 0) command.answered_pose_seq(1);
      if (out->write(command)) ++wrote;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    std::printf("command: writer %u wrote %llu, matched readers %d\n", participant.writer_id(),
                static_cast<unsigned long long>(wrote), out->matched_readers());
    return 0;
  } catch (const std::exception& e) {
    std::printf("%s: refused: %s\n", mode.c_str(), e.what());
    return 0;
  }
}
