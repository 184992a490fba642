// The lab file's loader: every key read against the keys valid at its place,
// every problem logged with file, line, column and key path, all reported
// at once.
#include <arpa/inet.h>

#include <fstream>
#include <set>
#include <sstream>

#include "fahr/lab_plan/lab.h"
#include "yaml_reader.h"

namespace fahr::lab {

namespace {

using scene::detail::closed;
using scene::detail::IssueLog;
using scene::detail::MapReader;

bool valid_name(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-';
    if (!ok) return false;
  }
  return true;
}

int line_of(const YAML::Mark& mark) {
  return mark.line >= 0 ? mark.line + 1 : 0;
}

// A required name, checked for its characters.
void read_name(const MapReader& map, std::string_view key, std::string& out) {
  if (!map.require(key) || !map.read(key, out)) return;
  if (!valid_name(out)) {
    map.log().add(map.value(key).Mark(), map.child_path(key),
                  "'" + out + "' is not a valid name: use 1-64 of A-Z a-z 0-9 _ -");
  }
}

void read_vendor(const MapReader& map, std::string_view key, common::Vendor& out) {
  std::string text;
  if (!map.read(key, text)) return;
  const auto vendor = common::parse_vendor(text);
  if (!vendor || *vendor == common::Vendor::kInProcess) {
    map.log().add(map.value(key).Mark(), map.child_path(key),
                  "'" + text + "' is not a DDS vendor: use fastdds or cyclonedds");
    return;
  }
  out = *vendor;
}

Host parse_host(IssueLog& log, const YAML::Node& node, std::size_t index) {
  const MapReader map(log, node, "hosts[" + std::to_string(index) + "]",
                      {"name", "address", "interface"});
  Host host;
  host.line = line_of(node.Mark());
  read_name(map, "name", host.name);
  if (map.require("address") && map.read("address", host.address)) {
    in_addr parsed{};
    if (inet_pton(AF_INET, host.address.c_str(), &parsed) != 1) {
      log.add(map.value("address").Mark(), map.child_path("address"),
              "'" + host.address + "' is not an IPv4 address (a.b.c.d)");
    }
  }
  if (map.require("interface")) map.read("interface", host.interface);
  return host;
}

ServiceSpec parse_service(const MapReader& services, ServiceKind kind, const Lab& lab,
                          common::Vendor station_vendor) {
  const std::string key = service_key(kind);
  IssueLog& log = services.log();
  const MapReader map(log, services.value(key), services.child_path(key),
                      {"host", "vendor", "cpus", "rt_priority", "args"});
  ServiceSpec spec;
  spec.kind = kind;
  spec.vendor = station_vendor;
  spec.line = line_of(services.value(key).Mark());
  if (map.require("host") && map.read("host", spec.host) && lab.host(spec.host) == nullptr) {
    std::string known;
    for (const auto& h : lab.hosts) known += (known.empty() ? "" : ", ") + h.name;
    log.add(map.value("host").Mark(), map.child_path("host"),
            "no host '" + spec.host + "' in hosts (" + known + ")");
  }
  read_vendor(map, "vendor", spec.vendor);
  map.read("cpus", spec.cpus);
  map.read("rt_priority", 0, 99, spec.rt_priority);
  if (map.has("args")) {
    const YAML::Node args = map.value("args");
    if (!args.IsSequence()) {
      log.add(args.Mark(), map.child_path("args"), "expected a list of arguments");
    } else {
      for (std::size_t i = 0; i < args.size(); ++i) {
        std::string arg;
        if (scene::detail::read_string(
                log, args[i], map.child_path("args") + "[" + std::to_string(i) + "]", arg)) {
          spec.args.push_back(arg);
        }
      }
    }
  }
  return spec;
}

Station parse_station(IssueLog& log, const YAML::Node& node, std::size_t index, const Lab& lab,
                      const std::filesystem::path& base_dir) {
  const MapReader map(log, node, "stations[" + std::to_string(index) + "]",
                      {"name", "domain", "partition", "scene", "vendor", "discovery",
                       "discovery_server_host", "restart", "duration_s", "services"});
  Station station;
  station.line = line_of(node.Mark());
  read_name(map, "name", station.name);
  if (map.require("domain")) {
    int domain = 0;
    // Both vendors' port mapping stays below 65536 up to domain 230.
    if (map.read("domain", 0, 230, domain)) station.domain = static_cast<std::uint32_t>(domain);
  }
  station.partition = station.name;
  if (map.read("partition", station.partition) &&
      (station.partition.empty() ||
       station.partition.find_first_of("*?[]\\") != std::string::npos)) {
    log.add(map.value("partition").Mark(), map.child_path("partition"),
            "'" + station.partition +
                "' is not a plain partition name (empty, or DDS would read * ? [ ] \\ as a "
                "pattern matching other stations)");
  }
  std::string scene_text;
  if (map.require("scene") && map.read("scene", scene_text)) {
    station.scene = std::filesystem::path(scene_text);
    if (station.scene.is_relative()) station.scene = (base_dir / station.scene).lexically_normal();
    if (!std::filesystem::is_regular_file(station.scene)) {
      log.add(map.value("scene").Mark(), map.child_path("scene"),
              "no scene file at " + station.scene.string());
    }
  }
  read_vendor(map, "vendor", station.vendor);
  std::string discovery;
  if (map.read("discovery", discovery)) {
    if (discovery == "peers") {
      station.discovery = Discovery::kPeers;
    } else if (discovery == "server") {
      station.discovery = Discovery::kServer;
    } else {
      log.add(map.value("discovery").Mark(), map.child_path("discovery"),
              "'" + discovery + "' is not one of: peers, server");
    }
  }
  map.read("restart", station.restart);
  map.read("duration_s", closed(0, 86400), station.duration_s);
  if (map.require("services")) {
    const MapReader services(log, map.value("services"), map.child_path("services"),
                             {"logger", "fem", "haptic", "device_gateway", "summary"});
    for (ServiceKind kind : kServiceKinds) {
      const bool required = kind == ServiceKind::kFem || kind == ServiceKind::kHaptic ||
                            kind == ServiceKind::kDeviceGateway;
      if (required ? services.require(service_key(kind)) : services.has(service_key(kind))) {
        station.services.push_back(parse_service(services, kind, lab, station.vendor));
      }
    }
  }
  if (station.discovery == Discovery::kServer) {
    for (const auto& s : station.services) {
      if (s.vendor != common::Vendor::kFastDds) {
        log.add(map.value("discovery").Mark(), map.child_path("discovery"),
                std::string("the Fast DDS discovery server serves Fast DDS only, but ") +
                    service_key(s.kind) + " runs " + std::string(common::vendor_name(s.vendor)) +
                    ": use discovery: peers for a mixed-vendor station");
        break;
      }
    }
    if (map.require("discovery_server_host") &&
        map.read("discovery_server_host", station.discovery_server_host) &&
        lab.host(station.discovery_server_host) == nullptr) {
      log.add(map.value("discovery_server_host").Mark(), map.child_path("discovery_server_host"),
              "no host '" + station.discovery_server_host + "' in hosts");
    }
  } else if (map.has("discovery_server_host")) {
    map.reject("discovery_server_host", "only with discovery: server");
  }
  return station;
}

Lab parse_checked(const std::string& text, const std::string& display_name,
                  const std::filesystem::path& base_dir) {
  IssueLog log{display_name};
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& error) {
    log.add(error.mark, "", "YAML syntax error: " + error.msg);
    log.throw_if_any();
  }
  Lab lab;
  const MapReader top(log, root, "", {"format_version", "lab", "hosts", "stations"});
  if (!top.is_map()) log.throw_if_any();
  if (top.require("format_version")) {
    int version = 0;
    top.read("format_version", kLabFormatVersion, kLabFormatVersion, version);
  }
  if (top.has("lab")) {
    const MapReader about(log, top.value("lab"), "lab",
                          {"name", "clock_sync", "max_clock_error_ms"});
    about.read("name", lab.name);
    std::string sync;
    if (about.read("clock_sync", sync)) {
      if (sync == "none") {
        lab.clock_sync = ClockSync::kNone;
      } else if (sync == "chrony") {
        lab.clock_sync = ClockSync::kChrony;
      } else if (sync == "ptp") {
        lab.clock_sync = ClockSync::kPtp;
      } else {
        log.add(about.value("clock_sync").Mark(), "lab.clock_sync",
                "'" + sync + "' is not one of: none, chrony, ptp");
      }
    }
    about.read("max_clock_error_ms", closed(0.001, 1000), lab.max_clock_error_ms);
  }
  std::set<std::string> seen_hosts;
  std::set<std::string> seen_addresses;
  if (top.require("hosts")) {
    const YAML::Node hosts = top.value("hosts");
    if (!hosts.IsSequence() || hosts.size() == 0) {
      log.add(hosts.Mark(), "hosts", "expected a list of at least one host");
    } else {
      for (std::size_t i = 0; i < hosts.size(); ++i) {
        Host host = parse_host(log, hosts[i], i);
        const std::string path = "hosts[" + std::to_string(i) + "]";
        if (!host.name.empty() && !seen_hosts.insert(host.name).second) {
          log.add(hosts[i]["name"].Mark(), path + ".name",
                  "a second host named '" + host.name + "'");
        }
        if (!host.address.empty() && !seen_addresses.insert(host.address).second) {
          log.add(hosts[i]["address"].Mark(), path + ".address",
                  "a second host at " + host.address);
        }
        lab.hosts.push_back(std::move(host));
      }
    }
  }
  if (top.require("stations")) {
    const YAML::Node stations = top.value("stations");
    if (!stations.IsSequence() || stations.size() == 0) {
      log.add(stations.Mark(), "stations", "expected a list of at least one station");
    } else {
      std::map<std::pair<std::uint32_t, std::string>, std::string> bus_owner;
      std::set<std::string> seen;
      for (std::size_t i = 0; i < stations.size(); ++i) {
        Station station = parse_station(log, stations[i], i, lab, base_dir);
        const std::string path = "stations[" + std::to_string(i) + "]";
        if (!station.name.empty() && !seen.insert(station.name).second) {
          log.add(stations[i]["name"].Mark(), path + ".name",
                  "a second station named '" + station.name + "'");
        }
        const auto [it, fresh] =
            bus_owner.emplace(std::make_pair(station.domain, station.partition), station.name);
        if (!fresh) {
          log.add(stations[i].Mark(), path,
                  "station '" + station.name + "' has the domain " +
                      std::to_string(station.domain) + " and partition '" + station.partition +
                      "' of station '" + it->second +
                      "': the two would drive each other's services; give one another domain "
                      "or partition");
        }
        lab.stations.push_back(std::move(station));
      }
    }
  }
  log.throw_if_any();
  lab.file = display_name;
  return lab;
}

}  // namespace

const char* service_key(ServiceKind kind) {
  switch (kind) {
    case ServiceKind::kLogger:
      return "logger";
    case ServiceKind::kFem:
      return "fem";
    case ServiceKind::kHaptic:
      return "haptic";
    case ServiceKind::kDeviceGateway:
      return "device_gateway";
    case ServiceKind::kSummary:
      return "summary";
  }
  return "?";
}

const ServiceSpec* Station::service(ServiceKind kind) const {
  for (const auto& s : services) {
    if (s.kind == kind) return &s;
  }
  return nullptr;
}

const Host* Lab::host(const std::string& wanted) const {
  for (const auto& h : hosts) {
    if (h.name == wanted) return &h;
  }
  return nullptr;
}

const Station* Lab::station(const std::string& wanted) const {
  for (const auto& s : stations) {
    if (s.name == wanted) return &s;
  }
  return nullptr;
}

Lab parse_lab(const std::string& text, const std::string& display_name,
              const std::filesystem::path& base_dir) {
  return parse_checked(text, display_name, base_dir);
}

Lab load_lab(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) {
    throw scene::SceneError(
        {scene::SceneIssue{file.string(), 0, 0, "", "cannot read the lab file"}});
  }
  std::stringstream text;
  text << in.rdbuf();
  Lab lab = parse_checked(text.str(), file.string(), std::filesystem::absolute(file).parent_path());
  lab.file = std::filesystem::absolute(file);
  return lab;
}

}  // namespace fahr::lab
