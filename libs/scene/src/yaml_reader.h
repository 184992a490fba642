// Checked reading of YAML nodes: every value is read with its key path, type
// and range, and every problem is logged with the file, line and column
// instead of thrown, so one pass over a scene reports all it can.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <chrono>
#include <cstddef>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "enum_names.h"
#include "fahr/scene/scene_error.h"

namespace fahr::scene::detail {

// The issues found in one scene source.
class IssueLog {
 public:
  explicit IssueLog(std::string file) : file_(std::move(file)) {}

  void add(const YAML::Mark& mark, std::string key_path, std::string message);
  const std::string& file() const { return file_; }
  bool empty() const { return issues_.empty(); }
  // Throws SceneError with everything logged so far, if anything.
  void throw_if_any() const;

 private:
  std::string file_;
  std::vector<SceneIssue> issues_;
};

// An interval of valid values, open or closed at either end.
struct Range {
  double lo;
  double hi;
  bool lo_open;
  bool hi_open;

  bool contains(double value) const;
  std::string describe() const;  // "(0, 0.5]"
};
inline constexpr Range closed(double lo, double hi) {
  return {lo, hi, false, false};
}
inline constexpr Range open(double lo, double hi) {
  return {lo, hi, true, true};
}
inline constexpr Range open_closed(double lo, double hi) {
  return {lo, hi, true, false};
}

// "a mapping", "a sequence", "nothing (null)", "'text'": what a node is, for messages.
std::string describe(const YAML::Node& node);
// Index of the candidate closest to word by edit distance, when close enough
// to be a likely typo.
std::optional<std::size_t> nearest(std::string_view word,
                                   const std::vector<std::string_view>& candidates);

// Scalars and vectors outside a mapping (sequence items); return false and log
// when the node is missing, of the wrong type or out of range.
bool read_double(IssueLog& log, const YAML::Node& node, const std::string& path, const Range& range,
                 double& out);
bool read_int(IssueLog& log, const YAML::Node& node, const std::string& path, long long lo,
              long long hi, long long& out);
bool read_string(IssueLog& log, const YAML::Node& node, const std::string& path, std::string& out);
bool read_vec3(IssueLog& log, const YAML::Node& node, const std::string& path, const Range& range,
               Eigen::Vector3d& out);

// A YAML mapping read against the keys valid at its place. Unknown keys (with
// the valid ones listed and the nearest suggested), duplicate keys and a node
// that is not a mapping are logged on construction.
class MapReader {
 public:
  MapReader(IssueLog& log, const YAML::Node& node, std::string path,
            std::initializer_list<std::string_view> valid_keys);

  bool is_map() const { return is_map_; }
  bool has(std::string_view key) const;
  // The value at key, or an undefined node.
  YAML::Node value(std::string_view key) const;
  // Mark of the key itself (or of the mapping when absent).
  YAML::Mark key_mark(std::string_view key) const;
  std::string child_path(std::string_view key) const;
  const std::string& path() const { return path_; }
  const YAML::Mark& mark() const { return mark_; }
  IssueLog& log() const { return *log_; }

  // Logs "missing required key" when absent; returns whether present.
  bool require(std::string_view key) const;
  // Logs that key is not valid here (for keys valid only in some variants).
  void reject(std::string_view key, std::string_view why) const;

  // Optional keys: out is left as is when the key is absent or invalid. Each
  // returns true when the key was present and valid.
  bool read(std::string_view key, const Range& range, double& out) const;
  bool read(std::string_view key, long long lo, long long hi, int& out) const;
  bool read(std::string_view key, bool& out) const;
  bool read(std::string_view key, std::string& out) const;
  bool read(std::string_view key, const Range& range, Eigen::Vector3d& out) const;
  // A duration written as a number of milliseconds or seconds.
  bool read_ms(std::string_view key, const Range& range_ms, std::chrono::nanoseconds& out) const;
  bool read_s(std::string_view key, const Range& range_s, std::chrono::nanoseconds& out) const;

  template <typename E, std::size_t N>
  bool read_enum(std::string_view key, const NameTable<E, N>& table, E& out) const {
    std::string text;
    if (!read(key, text)) return false;
    if (const std::optional<E> parsed = value_of(table, text)) {
      out = *parsed;
      return true;
    }
    log_->add(value(key).Mark(), child_path(key),
              "'" + text + "' is not one of: " + names_listed(table));
    return false;
  }

 private:
  struct Entry {
    std::string key;
    YAML::Node key_node;
    YAML::Node value;
  };
  const Entry* find(std::string_view key) const;
  void check_keys(const std::vector<std::string_view>& valid_keys);

  IssueLog* log_;
  std::string path_;
  YAML::Mark mark_;
  bool is_map_ = false;
  std::vector<Entry> entries_;
};

}  // namespace fahr::scene::detail
