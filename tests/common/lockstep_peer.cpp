// lockstep_peer <fast|slow> <vendor> <domain> <jitter_seed>: one lockstep
// participant in its own process; prints its output hash when stopped.
#include <cstdio>
#include <cstdlib>
#include <exception>

#include "lockstep_scenario.h"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: lockstep_peer <fast|slow> <vendor> <domain> <jitter_seed>\n");
    return 2;
  }
  try {
    fahr::common::TransportConfig config;
    config.vendor = fahr::common::resolve_vendor(argv[2]);
    config.domain_id = static_cast<std::uint32_t>(std::atoi(argv[3]));
    config.participant_name = std::string("lockstep_") + argv[1];
    fahr::common::Participant participant(config);
    const auto hash = fahr::test::run_lockstep_participant(
        participant, argv[1], static_cast<std::uint32_t>(std::atoi(argv[4])));
    std::printf("%s %016llx\n", argv[1], static_cast<unsigned long long>(hash));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "lockstep_peer: %s\n", e.what());
    return 1;
  }
}
