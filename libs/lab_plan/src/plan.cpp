// Participant indices, ports and peers of a lab.
#include "fahr/lab_plan/plan.h"

#include <cstdio>
#include <map>
#include <sstream>

namespace fahr::lab {

std::uint16_t discovery_port(std::uint32_t domain, int index) {
  return static_cast<std::uint16_t>(7400 + 250 * domain + 10 +
                                    2 * static_cast<std::uint32_t>(index));
}

std::uint16_t user_port(std::uint32_t domain, int index) {
  return static_cast<std::uint16_t>(7400 + 250 * domain + 11 +
                                    2 * static_cast<std::uint32_t>(index));
}

const PlannedParticipant* Plan::find(const std::string& station, ServiceKind kind) const {
  for (const auto& p : participants) {
    if (p.station->name == station && p.service->kind == kind) return &p;
  }
  return nullptr;
}

std::vector<Locator> Plan::peers(std::uint32_t domain, const PlannedParticipant* self) const {
  std::vector<Locator> out;
  for (const auto& p : participants) {
    if (&p == self || p.station->domain != domain) continue;
    out.push_back({p.host->address, discovery_port(domain, p.index)});
  }
  return out;
}

Locator Plan::discovery_server(const Station& station) const {
  const Host* host = lab->host(station.discovery_server_host);
  return {host != nullptr ? host->address : std::string(),
          static_cast<std::uint16_t>(kDiscoveryServerBasePort + station.domain)};
}

Plan make_plan(const Lab& lab) {
  Plan plan;
  plan.lab = &lab;
  std::map<std::pair<std::string, std::uint32_t>, int> next_index;
  std::vector<scene::SceneIssue> issues;
  for (const auto& station : lab.stations) {
    for (const auto& service : station.services) {
      PlannedParticipant p;
      p.station = &station;
      p.service = &service;
      p.host = lab.host(service.host);
      p.index = next_index[{service.host, station.domain}]++;
      if (p.index > kMaxParticipantIndex) {
        issues.push_back({lab.file.string(), service.line, 0,
                          "stations." + station.name + ".services." + service_key(service.kind),
                          "host '" + service.host + "' would run more than " +
                              std::to_string(kMaxParticipantIndex + 1) +
                              " participants on domain " + std::to_string(station.domain)});
      }
      plan.participants.push_back(p);
    }
  }
  if (!issues.empty()) throw scene::SceneError(std::move(issues));
  return plan;
}

std::string describe_plan(const Plan& plan) {
  std::ostringstream out;
  const Lab& lab = *plan.lab;
  const char* sync = lab.clock_sync == ClockSync::kChrony ? "chrony"
                     : lab.clock_sync == ClockSync::kPtp  ? "ptp"
                                                          : "none";
  out << "lab " << (lab.name.empty() ? lab.file.filename().string() : lab.name) << ": "
      << lab.hosts.size() << " hosts, " << lab.stations.size() << " stations, clock sync " << sync;
  if (lab.clock_sync != ClockSync::kNone)
    out << " (error budget " << lab.max_clock_error_ms << " ms)";
  out << "\n";
  for (const auto& station : lab.stations) {
    out << "\nstation " << station.name << ": domain " << station.domain << ", partition '"
        << station.partition << "', scene " << station.scene.string() << "\n  discovery: ";
    if (station.discovery == Discovery::kServer) {
      const Locator server = plan.discovery_server(station);
      out << "Fast DDS discovery server on " << station.discovery_server_host << " ("
          << server.address << ":" << server.port << ")";
    } else {
      out << "static unicast peers, multicast off";
    }
    out << "; on a dead service: " << (station.restart ? "restart it" : "stop the station") << "\n";
    char line[256];
    std::snprintf(line, sizeof line, "  %-15s %-10s %-15s %-10s %5s %9s %9s\n", "service", "host",
                  "address", "vendor", "index", "disc.port", "user.port");
    out << line;
    for (const auto& p : plan.participants) {
      if (p.station != &station) continue;
      std::snprintf(line, sizeof line, "  %-15s %-10s %-15s %-10s %5d %9u %9u\n",
                    service_key(p.service->kind), p.host->name.c_str(), p.host->address.c_str(),
                    std::string(common::vendor_name(p.service->vendor)).c_str(), p.index,
                    discovery_port(station.domain, p.index), user_port(station.domain, p.index));
      out << line;
    }
    const auto peers = plan.peers(station.domain, nullptr);
    out << "  peers on domain " << station.domain << ":";
    for (const auto& l : peers) out << " " << l.address << ":" << l.port;
    out << "\n";
  }
  out << "\nper host:\n";
  for (const auto& host : lab.hosts) {
    out << "  " << host.name << " (" << host.address << ", " << host.interface << "):";
    bool any = false;
    for (const auto& p : plan.participants) {
      if (p.host != &host) continue;
      out << " " << p.station->name << "/" << service_key(p.service->kind);
      any = true;
    }
    for (const auto& station : lab.stations) {
      if (station.discovery == Discovery::kServer && station.discovery_server_host == host.name) {
        out << " " << station.name << "/discovery_server";
        any = true;
      }
    }
    out << (any ? "\n" : " nothing (unused host)\n");
  }
  return out.str();
}

}  // namespace fahr::lab
