// fahr_lockstep_clock: the coordinator of a lockstep run. Waits until the
// named services have joined, grants base steps 0..N-1 in order (each once
// every service has finished the steps before it), then tells them to stop
// and prints each service's output hash: equal hashes on two runs mean the
// runs were identical, bit for bit, whatever the load and the vendor.
//
//   fahr_lockstep_clock --participants device_gateway,fem,haptic --steps N
//                       [--base-period-ms 1] [--stall-timeout-s 60] [--pace R]
//                       [--dds V] [--domain N] [--dds-profile F]
//
// --pace R: simulated time runs at most R times as fast as wall time (1.0:
// no faster than real time, so a browser watching the run sees it at the
// speed it happens); without it, as fast as the machine allows.
//
// Exit status: 0 when every step was granted and completed, 1 on a stall
// (a participant made no progress within the timeout), 2 on bad flags.
#include <chrono>
#include <cstdio>
#include <exception>
#include <sstream>
#include <string>
#include <vector>

#include "fahr/cli/cli.h"
#include "fahr/common/config_error.h"
#include "fahr/common/lockstep.h"
#include "fahr/common/participant.h"
#include "fahr/common/transport_config.h"

namespace {

int run(int argc, char** argv) {
  using namespace fahr;
  fahr::cli::App app{"fahr lockstep coordinator"};
  std::string participants_csv, dds, domain, profile;
  std::uint64_t steps = 0;
  double base_period_ms = 1.0;
  double stall_timeout_s = 60.0;
  double pace = 0.0;
  app.add_option("--participants", participants_csv,
                 "comma-separated lockstep names (device_gateway, fem, haptic)")
      ->required();
  app.add_option("--steps", steps, "base steps to grant")
      ->required()
      ->check(fahr::cli::PositiveNumber);
  app.add_option("--base-period-ms", base_period_ms, "simulated time of one base step, ms")
      ->check(fahr::cli::PositiveNumber);
  app.add_option("--stall-timeout-s", stall_timeout_s, "fail when nothing progresses this long")
      ->check(fahr::cli::PositiveNumber);
  app.add_option("--pace", pace,
                 "at most this many simulated seconds per wall second (default: unpaced)")
      ->check(fahr::cli::PositiveNumber);
  app.add_option("--dds", dds, "DDS vendor: fastdds, cyclonedds, inprocess");
  app.add_option("--domain", domain, "DDS domain id 0-230");
  app.add_option("--dds-profile", profile, "vendor XML configuration");
  std::string security;
  app.add_option("--security", security,
                 "DDS Security: the station's folder "
                 "(deployment/security/make_station_security.sh; default $FAHR_DDS_SECURITY)");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);

  std::vector<std::string> names;
  std::stringstream csv(participants_csv);
  for (std::string name; std::getline(csv, name, ',');) {
    if (!name.empty()) names.push_back(name);
  }
  if (names.empty()) {
    std::fprintf(stderr, "fahr_lockstep_clock: --participants: no name given\n");
    return 2;
  }
  try {
    common::Participant participant(
        common::transport_config_from(dds, domain, profile, "lockstep_clock", security));
    const auto base = std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::chrono::duration<double, std::milli>(base_period_ms));
    common::LockstepCoordinator coordinator(participant, base);
    const auto start = std::chrono::steady_clock::now();
    const auto result = coordinator.run(
        names, steps,
        std::chrono::milliseconds(static_cast<std::int64_t>(stall_timeout_s * 1000.0)), pace);
    const double wall_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("lockstep_clock: %s after %llu of %llu steps, %.2f s wall (%.2fx real time)\n",
                result.completed ? "completed" : "STALLED",
                static_cast<unsigned long long>(result.steps),
                static_cast<unsigned long long>(steps), wall_s,
                static_cast<double>(result.steps) * base_period_ms * 1e-3 / wall_s);
    for (const auto& [name, hash] : result.hashes) {
      std::printf("lockstep_clock: hash %s %016llx\n", name.c_str(),
                  static_cast<unsigned long long>(hash));
    }
    return result.completed ? 0 : 1;
  } catch (const common::ConfigError& e) {
    std::fprintf(stderr, "fahr_lockstep_clock: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {  // anything else: a message rather than terminate()
    std::fprintf(stderr, "fahr_lockstep_clock: %s\n", e.what());
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  // The option set-up may throw too (CLI11, allocation): a message, not terminate().
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_lockstep_clock: %s\n", e.what());
    return 1;
  }
}
