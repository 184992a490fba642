// Errors in configuration found at start-up (never thrown in a running loop).
#pragma once

#include <stdexcept>
#include <string>

namespace fahr::common {

class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace fahr::common
