// Text already in memory plus the name errors should show: lets loaders parse
// without touching the filesystem (fuzzers, tests, embedded scenes).
#pragma once

#include <string>
#include <string_view>

namespace fahr::geometry {

struct TextSource {
  std::string_view text;
  std::string_view name;  // shown in error messages, e.g. the file path
};

// Reads a whole file; throws LoadError naming the file when it cannot be read.
std::string read_text_file(const std::string& path);

}  // namespace fahr::geometry
