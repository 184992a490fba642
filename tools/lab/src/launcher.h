// fahr_lab up / down / status: a station's services on this host as child
// processes of one supervisor, with their logs and a status file in one run
// folder per station.
#pragma once

#include <filesystem>
#include <string>

#include "fahr/lab_plan/plan.h"

namespace fahr::lab {

struct UpOptions {
  std::string host;                // empty: found from this machine's addresses
  std::filesystem::path run_root;  // the station's run folder is run_root/<station>
  bool detach = false;             // run the supervisor in the background
};

// The host of `lab` this machine is: `wanted` if given, else $FAHR_HOST, else
// the host whose address is one of this machine's, else the one named like
// this machine. Throws std::runtime_error when none fits.
const Host& this_host(const Lab& lab, const std::string& wanted);

// $FAHR_RUN_ROOT, else /var/lib/fahr/runs as root, else /tmp/fahr-lab.
std::filesystem::path default_run_root();

// Starts the station's services that run on this host and supervises them
// until the station ends (the gateway's duration, SIGINT/SIGTERM, `down`,
// or the death of a service unless restart is on). Returns the exit status.
int station_up(const Plan& plan, const Station& station, const UpOptions& options);
// Asks the station's supervisor to stop and waits for it. Exit status.
int station_down(const std::string& station, const std::filesystem::path& run_root);
// Prints the station's services, their pids and states. Exit status: 0 all
// running, 1 not running, 3 running with a service down.
int station_status(const std::string& station, const std::filesystem::path& run_root);

}  // namespace fahr::lab
