// fahr_dds_check: joins a DDS domain the way every fahr service does and
// reports what it found, so a lab station's settings can be checked before
// a session. Bad settings exit with status 2 and a message naming them.
//
//   fahr_dds_check [--dds fastdds|cyclonedds|inprocess] [--domain N]
//                  [--dds-profile FILE] [--listen-s S]
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <exception>
#include <thread>

#include "fahr/common/config_error.h"
#include "fahr/common/participant.h"
#include "fahr/common/subscriber.h"

// A function-try-block: what the set-up before the inner try throws ends in a message too.
int main(int argc, char** argv) try {
  CLI::App app{"Join a fahr DDS domain and report what is there"};
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
  CLI11_PARSE(app, argc, argv);
  try {
    auto config =
        fahr::common::transport_config_from(dds, domain, profile, "fahr_dds_check", security);
    fahr::common::Participant participant(config);
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
