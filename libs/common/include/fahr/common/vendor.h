// The DDS vendor carrying a participant's topics, chosen at run time.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace fahr::common {

enum class Vendor {
  kFastDds,    // eProsima Fast DDS 2.9
  kCyclone,    // Eclipse Cyclone DDS 0.10
  kInProcess,  // no DDS: services in one process, same API (embedded default, unit tests)
};

// The environment variable that selects the vendor when no flag is given.
inline constexpr std::string_view kVendorEnvVar = "FAHR_DDS";

std::string_view vendor_name(Vendor vendor);

// "fastdds" / "cyclonedds" / "inprocess" (also "fast", "cyclone").
std::optional<Vendor> parse_vendor(std::string_view name);

// "fastdds, cyclonedds, inprocess": for error messages.
std::string valid_vendor_names();

// The flag wins over FAHR_DDS; neither set gives `fallback`. An unknown name
// throws ConfigError naming where it came from and listing the valid names.
Vendor resolve_vendor(std::string_view flag_value, Vendor fallback = Vendor::kFastDds);

}  // namespace fahr::common
