// fahr_replay: publishes a recording's samples back onto DDS.
//
//   fahr_replay FILE.mcap [--mode realtime|lockstep] [--topics LIST] [--speed X]
//               [--dds V] [--domain N] [--dds-profile F]
//
// realtime: the chosen topics (default fahr/DevicePose) at their original
// spacing in source time (scaled by 1/--speed), with the topics' own QoS.
// lockstep: stands in for the device gateway under fahr_lockstep_clock:
// at each granted base step k it publishes the recorded DevicePose of
// step k (SampleHeader.sim_step) with the lockstep output QoS and reports
// the step with the same output hash the gateway computes, so a recorded
// lockstep run's poses fed to a lockstep haptic and FEM reproduce their
// output hashes. Publishing restamps each header's seq, source time and
// writer id (the transport's stamp); seq runs 1, 2, ... as the gateway's did.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <exception>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "contact_setPubSubTypes.h"
#include "deformation_statePubSubTypes.h"
#include "device_posePubSubTypes.h"
#include "fahr/cli/cli.h"
#include "fahr/common/cdr_bytes.h"
#include "fahr/common/clock.h"
#include "fahr/common/lockstep.h"
#include "fahr/common/publisher.h"
#include "fahr/common/stop_signal.h"
#include "fahr/mcap/reader.h"
#include "force_commandPubSubTypes.h"
#include "scene_descriptionPubSubTypes.h"

namespace fahr {
namespace {

using namespace std::chrono_literals;

template <class T, class PubSub>
bool decode(const mcap::MessageView& m, T& out) {
  return common::decode_cdr<PubSub>(m.data, out);
}

// One recorded sample, ready to publish at its source time.
struct Timed {
  std::int64_t source_ns;
  std::function<void()> publish;
};

template <class T, class PubSub>
void collect(const mcap::MessageView& m, common::Publisher<T>& out, std::vector<Timed>& timeline) {
  auto sample = std::make_shared<T>();
  if (!decode<T, PubSub>(m, *sample)) return;
  timeline.push_back({sample->header().source_time_ns(), [&out, sample] { out.write(*sample); }});
}

int replay_realtime(const std::string& path, const std::set<std::string>& topics, double speed,
                    common::Participant& participant) {
  common::Publisher<msg::DevicePose> poses(participant);
  common::Publisher<msg::ForceCommand> commands(participant);
  common::Publisher<msg::ContactSet> contacts(participant);
  common::Publisher<msg::DeformationState> states(participant);
  common::Publisher<msg::SceneDescription> scene(participant);
  std::vector<Timed> timeline;
  const auto report =
      mcap::read_file(path, [&](const mcap::Channel& c, const mcap::MessageView& m) {
        if (topics.count(c.topic) == 0) return;
        if (c.topic == "fahr/DevicePose")
          collect<msg::DevicePose, msg::DevicePosePubSubType>(m, poses, timeline);
        if (c.topic == "fahr/ForceCommand")
          collect<msg::ForceCommand, msg::ForceCommandPubSubType>(m, commands, timeline);
        if (c.topic == "fahr/ContactSet")
          collect<msg::ContactSet, msg::ContactSetPubSubType>(m, contacts, timeline);
        if (c.topic == "fahr/DeformationState")
          collect<msg::DeformationState, msg::DeformationStatePubSubType>(m, states, timeline);
        if (c.topic == "fahr/SceneDescription")
          collect<msg::SceneDescription, msg::SceneDescriptionPubSubType>(m, scene, timeline);
      });
  if (timeline.empty()) {
    std::fprintf(stderr, "fahr_replay: no samples of the chosen topics in %s (%s)\n", path.c_str(),
                 report.error.c_str());
    return 1;
  }
  std::stable_sort(timeline.begin(), timeline.end(),
                   [](const Timed& a, const Timed& b) { return a.source_ns < b.source_ns; });
  std::this_thread::sleep_for(1s);  // let readers match
  const bool tty = isatty(STDERR_FILENO) != 0;
  const auto start = std::chrono::steady_clock::now();
  const std::int64_t first = timeline.front().source_ns;
  std::size_t n = 0;
  for (const auto& t : timeline) {
    if (common::stop_requested()) break;
    const auto at = start + std::chrono::nanoseconds(static_cast<std::int64_t>(
                                static_cast<double>(t.source_ns - first) / speed));
    std::this_thread::sleep_until(at);
    t.publish();
    if (tty && ++n % 1000 == 0) {
      std::fprintf(stderr, "\rfahr_replay: %zu of %zu samples", n, timeline.size());
    }
  }
  if (tty) std::fprintf(stderr, "\n");
  std::printf("fahr_replay: published %zu samples in %.2f s\n", timeline.size(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  return 0;
}

int replay_lockstep(const std::string& path, common::Participant& participant) {
  std::map<std::uint64_t, msg::DevicePose> by_step;
  msg::DevicePose pose;
  const auto report =
      mcap::read_file(path, [&](const mcap::Channel& c, const mcap::MessageView& m) {
        if (c.topic != "fahr/DevicePose") return;
        if (decode<msg::DevicePose, msg::DevicePosePubSubType>(m, pose))
          by_step[pose.header().sim_step()] = pose;
      });
  if (by_step.empty() || by_step.begin()->first != 0) {
    std::fprintf(stderr, "fahr_replay: %s holds no DevicePose of step 0 (%s)\n", path.c_str(),
                 report.error.c_str());
    return 1;
  }
  common::Publisher<msg::DevicePose> out(participant,
                                         common::lockstep_output_qos<msg::DevicePose>());
  common::LockstepClient client(participant, "device_gateway");
  client.join();
  common::OutputHash hash;
  std::uint64_t k = 0;
  for (; !common::stop_requested() && client.wait_for_grant(k, 20s); ++k) {
    auto it = by_step.find(k);
    if (it == by_step.end()) {
      std::fprintf(stderr, "fahr_replay: the recording has no DevicePose of step %llu\n",
                   static_cast<unsigned long long>(k));
      return 1;
    }
    out.write(it->second);
    hash.add(it->second);
    client.complete_through(k, hash.value());
  }
  std::printf("fahr_replay: lockstep: %llu steps, DevicePose hash %016llx\n",
              static_cast<unsigned long long>(k), static_cast<unsigned long long>(hash.value()));
  return 0;
}

int run(int argc, char** argv) {
  fahr::cli::App app{"fahr_replay: publish a recording's samples again"};
  std::string path, mode = "realtime", topics_csv = "fahr/DevicePose", dds, domain, profile;
  double speed = 1.0;
  app.add_option("file", path, "fahr recording (MCAP)")->required();
  app.add_option("--mode", mode, "realtime (original timing) or lockstep (as the device gateway)")
      ->check(fahr::cli::IsMember({"realtime", "lockstep"}));
  app.add_option("--topics", topics_csv,
                 "realtime: comma-separated topics (fahr/DevicePose, fahr/ForceCommand, "
                 "fahr/ContactSet, fahr/DeformationState, fahr/SceneDescription)");
  app.add_option("--speed", speed, "realtime: playback speed")->check(fahr::cli::PositiveNumber);
  app.add_option("--dds", dds, "DDS vendor: fastdds, cyclonedds");
  app.add_option("--domain", domain, "DDS domain 0-230");
  app.add_option("--dds-profile", profile, "vendor XML profile");
  std::string security;
  app.add_option("--security", security,
                 "DDS Security: the station's folder "
                 "(deployment/security/make_station_security.sh; default $FAHR_DDS_SECURITY)");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  common::install_stop_handlers();
  common::Participant participant(
      common::transport_config_from(dds, domain, profile, "replay", security));
  if (mode == "lockstep") return replay_lockstep(path, participant);
  std::set<std::string> topics;
  std::stringstream csv(topics_csv);
  for (std::string t; std::getline(csv, t, ',');) {
    if (!t.empty()) topics.insert(t);
  }
  return replay_realtime(path, topics, speed, participant);
}

}  // namespace
}  // namespace fahr

int main(int argc, char** argv) {
  try {
    return fahr::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_replay: %s\n", e.what());
    return 1;
  }
}
