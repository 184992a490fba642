// What a lab file means on the wire: every participant of every station with
// its host, vendor, fixed participant index and ports, and the unicast peers
// each one announces itself to. Both vendors use the RTPS default port
// mapping (PB 7400, DG 250, PG 2, d1 10, d3 11), so one plan serves both.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fahr/lab_plan/lab.h"

namespace fahr::lab {

// Highest participant index whose ports stay inside the domain's 250-port
// block (7400 + 250 d + 11 + 2 i < 7400 + 250 (d + 1)); Cyclone 0.10 takes
// fixed indices below 120.
inline constexpr int kMaxParticipantIndex = 119;
// Fast DDS discovery server (fast-discovery-server) port: this plus the
// domain, one server per domain and host.
inline constexpr int kDiscoveryServerBasePort = 11811;

std::uint16_t discovery_port(std::uint32_t domain, int index);  // SPDP unicast (d1)
std::uint16_t user_port(std::uint32_t domain, int index);       // user traffic unicast (d3)

struct PlannedParticipant {
  const Station* station = nullptr;
  const ServiceSpec* service = nullptr;
  const Host* host = nullptr;
  // Fixed per host and domain across the lab: services of stations that
  // share a host and domain never contend for an index, and none is ever
  // picked at run time, so none can run out.
  int index = 0;
};

struct Locator {
  std::string address;
  std::uint16_t port = 0;
};

struct Plan {
  const Lab* lab = nullptr;
  std::vector<PlannedParticipant> participants;

  const PlannedParticipant* find(const std::string& station, ServiceKind kind) const;
  // The discovery locators of every planned participant on `domain` except
  // `self` (may be null): a station's peers include those of other stations
  // on its domain, so partitions, not missing peers, keep stations apart.
  std::vector<Locator> peers(std::uint32_t domain, const PlannedParticipant* self) const;
  // kServer stations: the server's address and port.
  Locator discovery_server(const Station& station) const;
};

// Throws scene::SceneError when a host and domain would need more than
// kMaxParticipantIndex + 1 participants.
Plan make_plan(const Lab& lab);

// The plan as text: per station its domain, partition, discovery and per
// service the host, address, vendor, index and ports; then per host what
// runs there.
std::string describe_plan(const Plan& plan);

}  // namespace fahr::lab
