// Command-line options of fahr_device_gateway, parsed and checked before the
// loop starts (errors name the flag).
#pragma once

#include <chrono>
#include <optional>
#include <string>

namespace fahr::gateway_service {

struct GatewayOptions {
  std::string dds;                    // --dds fastdds|cyclonedds|inprocess (default: FAHR_DDS)
  std::string domain;                 // --domain N
  std::string profile;                // --profile FILE
  std::string security;               // --security DIR (DDS Security)
  std::string mode = "realtime";      // --mode realtime|lockstep
  std::string backend = "simulated";  // --backend simulated|replay|remote|openhaptics
  std::string script = "intubation";  // --script intubation|overshoot
  std::string model = "touch_x";      // --model touch_x|touch
  std::string replay_file;            // --replay-file FILE (replay back-end)
  std::string record_file;  // --record-file FILE: write the DevicePose stream after the run
  double duration_s =
      0.0;  // --duration-s S, > 0; 0 = the script's length (simulated/replay) or until SIGINT
  std::uint32_t device_id = 0;  // --device-id N
  int rt_priority = 0;          // --rt-priority N (1-99): SCHED_FIFO if permitted, else a warning
  int spin_us = 0;              // --spin-us N: busy-wait the last N us of each period (opt-in)
  double status_hz = 4.0;       // --status-hz HZ, (0, 100]
  // --wait-haptic-s S: how long a scripted hand waits at its first tick for
  // the haptic service (a match both ways, which the haptic service offers
  // only once it is ready). fahr_lab raises it when that service runs on
  // another host, whose start the gateway's host does not see.
  double wait_haptic_s = 5.0;
  std::uint64_t force_input_period = 1;  // --force-input-period N: lockstep period of
                                         // ForceCommand's producer in base steps; 0: none
};

// Parses argv; on error or --help returns nullopt after printing to stderr.
std::optional<GatewayOptions> parse_options(int argc, char** argv);

}  // namespace fahr::gateway_service
