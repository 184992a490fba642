// Vendor configuration generated from a lab plan: the same discovery on both
// vendors without multicast (static unicast peers, a fixed participant
// index, the lab interface only, socket buffers for large samples), or a
// Fast DDS discovery-server client for stations that run Fast DDS alone.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "fahr/lab_plan/plan.h"

namespace fahr::lab {

// Requested UDP socket buffers (the kernel caps them at net.core.rmem_max /
// wmem_max): a burst of large DeformationStates must fit
// (docs/design/mixed-vendor-load.md).
inline constexpr int kSocketBufferBytes = 4 * 1024 * 1024;
// How long a station's gateway waits for its haptic service on another host
// (--wait-haptic-s), s: as long as a supervisor waits for a service's ready line.
inline constexpr int kRemoteHapticWaitS = 120;

// The Fast DDS XML profile (default participant profile) of a participant.
std::string fast_profile(const Plan& plan, const PlannedParticipant& p);
// The Cyclone DDS configuration of a participant.
std::string cyclone_config(const Plan& plan, const PlannedParticipant& p);
// For tools joining a station on `host` (fahr_dds_check, a probe): the same
// peers, the participant index picked at start among free ones (Cyclone:
// auto up to kMaxParticipantIndex; Fast DDS: the first free id).
std::string fast_tool_profile(const Plan& plan, const Station& station, const Host& host);
std::string cyclone_tool_config(const Plan& plan, const Station& station, const Host& host);

// One generated file.
struct GeneratedFile {
  std::filesystem::path path;
  std::string text;
};

// Everything `fahr_lab config` writes for a station's services on a host,
// into `dir`: <service>.xml and <service>.env per service on the host,
// tool_fastdds.xml, tool_cyclonedds.xml, tool_<vendor>.env, plan.txt.
std::vector<GeneratedFile> station_files(const Plan& plan, const Station& station, const Host& host,
                                         const std::filesystem::path& dir);

// Writes the files (creating `dir`); throws std::runtime_error naming a file
// it cannot write.
void write_files(const std::vector<GeneratedFile>& files);

// The discovery server's id for a station (its place in the lab, < 256).
int discovery_server_id(const Plan& plan, const Station& station);

}  // namespace fahr::lab
