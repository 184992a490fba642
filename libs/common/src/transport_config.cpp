// Start-up validation of transport settings: every error names its field.
#include "fahr/common/transport_config.h"

#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "fahr/common/config_error.h"

namespace fahr::common {
namespace {

std::string env_or_empty(const char* name) {
  const char* value = std::getenv(name);
  return value == nullptr ? std::string() : std::string(value);
}

std::uint32_t parse_domain(std::string_view text, std::string_view source) {
  std::int64_t value = -1;
  const auto* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, value);
  if (result.ec != std::errc() || result.ptr != end) {
    throw ConfigError(std::string(source) + ": domain id '" + std::string(text) +
                      "' is not an integer");
  }
  if (value < 0 || value > kMaxDomainId) {
    throw ConfigError(std::string(source) + ": domain id " + std::to_string(value) +
                      " is out of range [0, " + std::to_string(kMaxDomainId) + "]");
  }
  return static_cast<std::uint32_t>(value);
}

}  // namespace

SecurityFiles security_files(const TransportConfig& config) {
  std::filesystem::path dir = std::filesystem::absolute(config.security_dir);
  const std::filesystem::path id = dir / "identities" / config.identity_name();
  return {(dir / "ca.cert.pem").string(), (dir / "governance.p7s").string(),
          (id / "cert.pem").string(), (id / "key.pem").string(), (id / "permissions.p7s").string()};
}

void validate(const TransportConfig& config) {
  if (!config.security_dir.empty()) {
    if (config.vendor == Vendor::kInProcess)
      throw ConfigError("--security: the in-process bus has no DDS Security");
    const SecurityFiles f = security_files(config);
    for (const std::string* file : {&f.ca_cert, &f.governance, &f.cert, &f.key, &f.permissions}) {
      if (!std::ifstream(*file)) {
        throw ConfigError("--security " + config.security_dir + ": '" + *file +
                          "' cannot be read (no identity '" + config.identity_name() +
                          "' in this station's folder? deployment/security/"
                          "make_station_security.sh makes them)");
      }
    }
  }
  if (config.domain_id > kMaxDomainId) {
    throw ConfigError("domain_id: " + std::to_string(config.domain_id) + " is out of range [0, " +
                      std::to_string(kMaxDomainId) + "]");
  }
  // DDS matches partition names with '*', '?' and '[' as patterns: a lab
  // station's partition is a plain name, or it could match another's.
  if (config.partition.find_first_of("*?[]\\") != std::string::npos) {
    throw ConfigError("partition '" + config.partition +
                      "': wildcard characters (* ? [ ] \\) would match other stations' partitions");
  }
  if (config.profile_file.empty()) return;
  std::ifstream in(config.profile_file);
  if (!in)
    throw ConfigError("DDS profile '" + config.profile_file + "': cannot be read (missing file?)");
  std::stringstream text;
  text << in.rdbuf();
  const std::string xml = text.str();
  const bool cyclone_xml = xml.find("<CycloneDDS") != std::string::npos;
  const bool fast_xml =
      xml.find("<profiles") != std::string::npos || xml.find("<dds") != std::string::npos;
  if (config.vendor == Vendor::kCyclone && !cyclone_xml) {
    throw ConfigError(
        "DDS profile '" + config.profile_file +
        "': not a Cyclone DDS configuration (no <CycloneDDS> element) but vendor is cyclonedds");
  }
  if (config.vendor == Vendor::kFastDds && !fast_xml) {
    throw ConfigError(
        "DDS profile '" + config.profile_file +
        "': not a Fast DDS profile file (no <profiles> or <dds> element) but vendor is fastdds");
  }
}

TransportConfig transport_config_from(std::string_view vendor_flag, std::string_view domain_flag,
                                      std::string_view profile_flag, std::string participant_name,
                                      std::string_view security_flag) {
  TransportConfig config;
  config.vendor = resolve_vendor(vendor_flag);
  config.participant_name = std::move(participant_name);
  if (!domain_flag.empty()) {
    config.domain_id = parse_domain(domain_flag, "--domain");
  } else if (auto env = env_or_empty("FAHR_DOMAIN_ID"); !env.empty()) {
    config.domain_id = parse_domain(env, "FAHR_DOMAIN_ID");
  }
  config.profile_file =
      profile_flag.empty() ? env_or_empty("FAHR_DDS_PROFILE") : std::string(profile_flag);
  config.partition = env_or_empty("FAHR_PARTITION");
  config.security_dir =
      security_flag.empty() ? env_or_empty("FAHR_DDS_SECURITY") : std::string(security_flag);
  config.identity = env_or_empty("FAHR_DDS_IDENTITY");
  validate(config);
  return config;
}

}  // namespace fahr::common
