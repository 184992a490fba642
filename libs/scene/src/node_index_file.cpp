#include "fahr/scene/node_index_file.h"

#include <algorithm>
#include <charconv>
#include <fstream>
#include <limits>
#include <string>

#include "fahr/scene/scene_error.h"

namespace fahr::scene {

namespace {

[[noreturn]] void fail(const std::filesystem::path& path, int line, std::string message) {
  throw SceneError({SceneIssue{path.string(), line, 0, "", std::move(message)}});
}

std::string_view trimmed(std::string_view text) {
  const auto first = text.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t\r");
  return text.substr(first, last - first + 1);
}

}  // namespace

std::vector<std::uint32_t> read_node_index_file(const std::filesystem::path& path, int index_base) {
  std::ifstream in(path);
  if (!in) fail(path, 0, "cannot open the fixed-node file");
  std::vector<std::uint32_t> indices;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    std::string_view text = line;
    text = trimmed(text.substr(0, text.find('#')));
    if (text.empty()) continue;
    std::uint64_t value = 0;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size()) {
      fail(path, line_number,
           "expected one non-negative node index, got '" + std::string(text) + "'");
    }
    if (value < static_cast<std::uint64_t>(index_base) ||
        value - static_cast<std::uint64_t>(index_base) >
            std::numeric_limits<std::uint32_t>::max()) {
      fail(path, line_number,
           "node index " + std::string(text) + " is out of range for index base " +
               std::to_string(index_base));
    }
    indices.push_back(static_cast<std::uint32_t>(value - static_cast<std::uint64_t>(index_base)));
  }
  if (in.bad()) fail(path, line_number, "read error");
  std::sort(indices.begin(), indices.end());
  indices.erase(std::unique(indices.begin(), indices.end()), indices.end());
  return indices;
}

}  // namespace fahr::scene
