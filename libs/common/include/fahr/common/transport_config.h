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
  // DDS Security: a station's folder (deployment/security/
  // make_station_security.sh): ca.cert.pem, governance.p7s and
  // identities/<identity>/{cert.pem,key.pem,permissions.p7s}. Empty: no
  // security (and a secured station does not let this participant in).
  std::string security_dir;
  // The identity in security_dir; empty: participant_name.
  std::string identity;

  const std::string& identity_name() const {
    return identity.empty() ? participant_name : identity;
  }
};

// The files of a participant's identity in a station's security folder.
struct SecurityFiles {
  std::string ca_cert, governance, cert, key, permissions;  // absolute paths
};
SecurityFiles security_files(const TransportConfig& config);

// Throws ConfigError naming the field: domain id out of range, profile file
// missing or unreadable, profile of the wrong kind for the vendor.
void validate(const TransportConfig& config);

// Reads FAHR_DDS, FAHR_DOMAIN_ID, FAHR_DDS_PROFILE, FAHR_PARTITION and FAHR_DDS_SECURITY
// (and FAHR_DDS_IDENTITY), overridden by the non-empty command-line values given. Throws
// ConfigError on bad values (a missing security file named).
TransportConfig transport_config_from(std::string_view vendor_flag, std::string_view domain_flag,
                                      std::string_view profile_flag, std::string participant_name,
                                      std::string_view security_flag = {});

}  // namespace fahr::common
