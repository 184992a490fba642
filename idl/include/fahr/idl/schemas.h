// Each topic type's OMG IDL as one self-contained text (every referenced
// definition inline, no preprocessor lines): the `omgidl` schemas that MCAP
// recordings and live viewers (Foxglove, Lichtblick) decode `cdr` samples
// with. Generated at build time from idl/fahr/*.idl (cmake/FahrIdlSchemas.cmake).
#pragma once

#include <span>
#include <string_view>

namespace fahr::idl {

struct TypeSchema {
  std::string_view type_name;   // "fahr::msg::DevicePose", as on the wire
  std::string_view short_name;  // "DevicePose"
  std::string_view idl;
};

std::span<const TypeSchema> type_schemas();

// The IDL of `type_name` (scoped or short name); empty if unknown.
inline std::string_view schema_of(std::string_view type_name) {
  for (const auto& s : type_schemas()) {
    if (s.type_name == type_name || s.short_name == type_name) return s.idl;
  }
  return {};
}

}  // namespace fahr::idl
