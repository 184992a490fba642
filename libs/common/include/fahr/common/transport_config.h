// What a participant needs to join the bus: vendor, domain, name, profile.
#pragma once

#include <cstdint>
#include <string>

#include "fahr/common/vendor.h"

namespace fahr::common {

// Both vendors' default RTPS port mapping (PB 7400, DG 250, PG 2) keeps
// every port below 65536 only up to domain 232; Cyclone refuses above 230.
inline constexpr std::uint32_t kMaxDomainId = 230;

struct TransportConfig {
  Vendor vendor = Vendor::kFastDds;
  std::uint32_t domain_id = 0;
  // Shown in discovery and in ServiceStatus.
  std::string participant_name = "fahr";
  // Optional vendor configuration file: a Fast DDS XML profile file, or a
  // Cyclone DDS XML configuration. Empty: the vendor's own environment
  // variable (FASTRTPS_DEFAULT_PROFILES_FILE / CYCLONEDDS_URI) or defaults.
  std::string profile_file;
  // Optional DDS partition for every endpoint, to separate lab stations that
  // share a domain (FAHR_PARTITION; fahr_lab sets it per station). A plain
  // name: wildcards are refused.
  std::string partition;
};

// Throws ConfigError naming the field: domain id out of range, profile file
// missing or unreadable, profile of the wrong kind for the vendor.
void validate(const TransportConfig& config);

// Reads FAHR_DDS, FAHR_DOMAIN_ID, FAHR_DDS_PROFILE and FAHR_PARTITION, overridden by the
// non-empty command-line values given. Throws ConfigError on bad values.
TransportConfig transport_config_from(std::string_view vendor_flag, std::string_view domain_flag,
                                      std::string_view profile_flag, std::string participant_name);

}  // namespace fahr::common
