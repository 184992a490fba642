// A lab file: the machines of a lab and the training stations that run on
// them, each service of a station on a named host and DDS vendor. Loaded and
// checked by load_lab(); the format is documented in docs/design/lab.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fahr/common/vendor.h"
#include "fahr/scene/scene_error.h"

namespace fahr::lab {

inline constexpr int kLabFormatVersion = 1;

enum class ClockSync { kNone, kChrony, kPtp };
enum class Discovery { kPeers, kServer };

struct Host {
  std::string name;
  std::string address;    // IPv4 address the station's traffic uses
  std::string interface;  // the interface holding it (vendors are kept to it)
  int line = 0;
};

// The services a station can run, in the order they start.
enum class ServiceKind { kLogger, kFem, kHaptic, kDeviceGateway, kSummary };
inline constexpr ServiceKind kServiceKinds[] = {ServiceKind::kLogger, ServiceKind::kFem,
                                                ServiceKind::kHaptic, ServiceKind::kDeviceGateway,
                                                ServiceKind::kSummary};
// "logger", "fem", "haptic", "device_gateway", "summary".
const char* service_key(ServiceKind kind);

struct ServiceSpec {
  ServiceKind kind = ServiceKind::kFem;
  std::string host;
  common::Vendor vendor = common::Vendor::kCyclone;
  std::string cpus;               // CPU list for the service's --cpus, empty: any
  int rt_priority = 0;            // SCHED_FIFO priority of a 1 kHz tick, 0: none
  std::vector<std::string> args;  // more arguments, as given
  int line = 0;
};

struct Station {
  std::string name;
  std::uint32_t domain = 0;
  std::string partition;        // default: the station's name
  std::filesystem::path scene;  // resolved against the lab file's folder
  common::Vendor vendor = common::Vendor::kCyclone;
  Discovery discovery = Discovery::kPeers;
  std::string discovery_server_host;  // kServer: where fast-discovery-server runs
  bool restart = false;               // restart a dead service instead of stopping the station
  double duration_s = 0;              // the gateway's run; 0: until stopped
  std::vector<ServiceSpec> services;  // in start order
  int line = 0;

  const ServiceSpec* service(ServiceKind kind) const;
};

struct Lab {
  std::filesystem::path file;
  std::string name;
  ClockSync clock_sync = ClockSync::kNone;
  double max_clock_error_ms = 1.0;
  std::vector<Host> hosts;
  std::vector<Station> stations;

  const Host* host(const std::string& name) const;
  const Station* station(const std::string& name) const;
};

// Reads and checks a lab file. Throws scene::SceneError listing every
// problem as file:line:column: key: message (a missing scene file, a host
// no service names, two stations on one domain and partition, ...).
Lab load_lab(const std::filesystem::path& file);
// The same from text (tests); scene paths resolve against base_dir.
Lab parse_lab(const std::string& text, const std::string& display_name,
              const std::filesystem::path& base_dir);

}  // namespace fahr::lab
