// fahr_dds_check: joins a DDS domain the way every fahr service does and
// reports what it found, so a lab station's settings can be checked before
// a session. Bad settings exit with status 2 and a message naming them.
//
//   fahr_dds_check [--dds fastdds|cyclonedds|inprocess] [--domain N]
//                  [--dds-profile FILE] [--listen-s S] [--station]
//
// --station: a reader on every station topic, in the partition of
// $FAHR_PARTITION (readers only: a writer of its own would match them).
// Prints when each reader first matched a writer (the discovery time of a
// participant joining a running station: "every reader matched in S s")
// and, after --listen-s, the writers matched and samples received: zero
// when the probe sits in another station's partition on the same domain.
#include <chrono>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>
#include <thread>
#include <tuple>

#include "fahr/cli/cli.h"
#include "fahr/common/config_error.h"
#include "fahr/common/participant.h"
#include "fahr/common/subscriber.h"

namespace {

using Clock = std::chrono::steady_clock;

// A reader on one topic.
template <class T>
struct Probe {
  explicit Probe(fahr::common::Participant& participant) : reader(participant) {}
  fahr::common::Subscriber<T> reader;
  double matched_after_s = -1;
  const char* name() const { return fahr::common::TopicTraits<T>::kName.data(); }
};

template <class... T>
struct StationProbe {
  explicit StationProbe(fahr::common::Participant& participant)
      : probes(std::make_unique<Probe<T>>(participant)...) {}
  std::tuple<std::unique_ptr<Probe<T>>...> probes;

  // Notes first matches; true when every reader has matched a writer.
  bool poll(double elapsed_s) {
    bool all = true;
    std::apply(
        [&](auto&... p) {
          ((p->matched_after_s < 0 && p->reader.matched_writers() > 0
                ? p->matched_after_s = elapsed_s
                : 0.0),
           ...);
          ((all = all && p->matched_after_s >= 0), ...);
        },
        probes);
    return all;
  }
  void print() const {
    long endpoints = 0;
    unsigned long long samples = 0;
    std::apply(
        [&](const auto&... p) {
          ((std::printf("topic %-24s reader matched %d writer(s)%s, samples %llu\n", p->name(),
                        p->reader.matched_writers(),
                        p->matched_after_s >= 0
                            ? (" after " + std::to_string(p->matched_after_s) + " s").c_str()
                            : "",
                        static_cast<unsigned long long>(p->reader.received())),
            endpoints += p->reader.matched_writers(), samples += p->reader.received()),
           ...);
        },
        probes);
    std::printf("endpoints matched: %ld, samples: %llu\n", endpoints, samples);
  }
};

}  // namespace

// A function-try-block: what the set-up before the inner try throws ends in a message too.
int main(int argc, char** argv) try {
  fahr::cli::App app{"Join a fahr DDS domain and report what is there"};
  std::string dds, domain, profile;
  double listen_s = 2.0;
  app.add_option("--dds", dds, "DDS vendor (default: $FAHR_DDS, else fastdds)");
  app.add_option("--domain", domain, "DDS domain id 0-230 (default: $FAHR_DOMAIN_ID, else 0)");
  app.add_option("--dds-profile", profile, "vendor XML configuration (default: $FAHR_DDS_PROFILE)");
  std::string security;
  app.add_option("--security", security,
                 "DDS Security: the station's folder "
                 "(deployment/security/make_station_security.sh; default $FAHR_DDS_SECURITY)");
  app.add_option("--listen-s", listen_s, "seconds to listen for services' ServiceStatus");
  bool station = false;
  app.add_flag("--station", station,
               "probe every station topic: discovery time, endpoints matched, samples");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  try {
    auto config =
        fahr::common::transport_config_from(dds, domain, profile, "fahr_dds_check", security);
    const auto joined = Clock::now();
    fahr::common::Participant participant(config);
    if (station) {
      using namespace fahr::msg;
      StationProbe<DevicePose, ForceCommand, ContactSet, DeformationState, SceneDescription,
                   ServiceStatus>
          probe(participant);
      std::printf("vendor %s, domain %u, partition '%s': probing\n",
                  std::string(fahr::common::vendor_name(config.vendor)).c_str(), config.domain_id,
                  config.partition.c_str());
      bool reported = false;
      for (;;) {
        const double elapsed = std::chrono::duration<double>(Clock::now() - joined).count();
        if (!reported && probe.poll(elapsed)) {
          std::printf("discovery: every reader matched in %.3f s\n", elapsed);
          reported = true;
        }
        if (elapsed >= listen_s) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      if (!reported) std::printf("discovery: not every reader matched in %.1f s\n", listen_s);
      probe.print();
      return 0;
    }
    fahr::common::Subscriber<fahr::msg::ServiceStatus> status(participant);
    std::printf("vendor %s, domain %u, profile %s: joined\n",
                std::string(fahr::common::vendor_name(config.vendor)).c_str(), config.domain_id,
                config.profile_file.empty() ? "(vendor default)" : config.profile_file.c_str());
    std::this_thread::sleep_for(std::chrono::duration<double>(listen_s));
    std::printf("ServiceStatus writers seen: %d, samples: %llu\n", status.matched_writers(),
                static_cast<unsigned long long>(status.received()));
    return 0;
  } catch (const fahr::common::ConfigError& e) {
    std::fprintf(stderr, "fahr_dds_check: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_dds_check: %s\n", e.what());
    return 1;
  }
} catch (const std::exception& e) {
  std::fprintf(stderr, "fahr_dds_check: %s\n", e.what());
  return 1;
}
