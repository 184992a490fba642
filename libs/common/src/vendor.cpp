// Vendor names and the flag/environment rule.
#include "fahr/common/vendor.h"

#include <cstdlib>

#include "fahr/common/config_error.h"

namespace fahr::common {

std::string_view vendor_name(Vendor vendor) {
  switch (vendor) {
    case Vendor::kFastDds:
      return "fastdds";
    case Vendor::kCyclone:
      return "cyclonedds";
    case Vendor::kInProcess:
      return "inprocess";
  }
  return "unknown";
}

std::optional<Vendor> parse_vendor(std::string_view name) {
  if (name == "fastdds" || name == "fast") return Vendor::kFastDds;
  if (name == "cyclonedds" || name == "cyclone") return Vendor::kCyclone;
  if (name == "inprocess") return Vendor::kInProcess;
  return std::nullopt;
}

std::string valid_vendor_names() {
  return "fastdds, cyclonedds, inprocess";
}

Vendor resolve_vendor(std::string_view flag_value, Vendor fallback) {
  std::string_view source = "--dds";
  std::string_view name = flag_value;
  if (name.empty()) {
    const char* env = std::getenv(std::string(kVendorEnvVar).c_str());
    if (env == nullptr || *env == '\0') return fallback;
    source = kVendorEnvVar;
    name = env;
  }
  if (auto vendor = parse_vendor(name)) return *vendor;
  throw ConfigError(std::string(source) + ": unknown DDS vendor '" + std::string(name) +
                    "'; valid vendors: " + valid_vendor_names());
}

}  // namespace fahr::common
