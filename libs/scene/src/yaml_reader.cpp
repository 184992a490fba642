#include "yaml_reader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <sstream>

namespace fahr::scene::detail {

namespace {

// yaml-cpp marks are 0-based with -1 for "none"; messages are 1-based with 0.
int one_based(int zero_based) {
  return zero_based >= 0 ? zero_based + 1 : 0;
}

// yaml-cpp tags a quoted scalar "!" and a plain one "?". A quoted number is
// almost always a mistake worth pointing out rather than silently accepting.
bool is_quoted(const YAML::Node& node) {
  return node.Tag() == "!";
}

std::string format_number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      const std::size_t substitution = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
      row[j] = std::min({above + 1, row[j - 1] + 1, substitution});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// The scalar text of a node that must be a plain scalar, or nullopt (logged).
std::optional<std::string> plain_scalar(IssueLog& log, const YAML::Node& node,
                                        const std::string& path, std::string_view expected) {
  if (!node.IsDefined() || !node.IsScalar() || is_quoted(node)) {
    log.add(node.Mark(), path, "expected " + std::string(expected) + ", got " + describe(node));
    return std::nullopt;
  }
  return node.Scalar();
}

}  // namespace

void IssueLog::add(const YAML::Mark& mark, std::string key_path, std::string message) {
  issues_.push_back(SceneIssue{file_, one_based(mark.line), one_based(mark.column),
                               std::move(key_path), std::move(message)});
}

void IssueLog::throw_if_any() const {
  if (!issues_.empty()) throw SceneError(issues_);
}

bool Range::contains(double value) const {
  const bool above_lo = lo_open ? value > lo : value >= lo;
  const bool below_hi = hi_open ? value < hi : value <= hi;
  return above_lo && below_hi;
}

std::string Range::describe() const {
  return std::string(lo_open ? "(" : "[") + format_number(lo) + ", " + format_number(hi) +
         (hi_open ? ")" : "]");
}

std::string describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing (null)";
  if (node.IsMap()) return "a mapping";
  if (node.IsSequence()) return "a sequence";
  if (is_quoted(node)) return "the quoted text \"" + node.Scalar() + "\"";
  return "'" + node.Scalar() + "'";
}

std::optional<std::size_t> nearest(std::string_view word,
                                   const std::vector<std::string_view>& candidates) {
  std::optional<std::size_t> best;
  std::size_t best_distance = std::numeric_limits<std::size_t>::max();
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const std::size_t d = edit_distance(word, candidates[i]);
    if (d < best_distance) {
      best_distance = d;
      best = i;
    }
  }
  // A third of the word's length, at least 2 edits: catches typos and
  // near-misses without suggesting an unrelated key.
  const std::size_t allowed = std::max<std::size_t>(2, word.size() / 3);
  if (!best || best_distance > allowed) return std::nullopt;
  return best;
}

bool read_double(IssueLog& log, const YAML::Node& node, const std::string& path, const Range& range,
                 double& out) {
  const std::optional<std::string> text = plain_scalar(log, node, path, "a number");
  if (!text) return false;
  std::string_view digits = *text;
  if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
  double value = 0.0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (error != std::errc() || end != digits.data() + digits.size() || !std::isfinite(value)) {
    log.add(node.Mark(), path, "expected a finite number, got " + describe(node));
    return false;
  }
  if (!range.contains(value)) {
    log.add(node.Mark(), path, "value " + *text + " is out of range; valid: " + range.describe());
    return false;
  }
  out = value;
  return true;
}

bool read_int(IssueLog& log, const YAML::Node& node, const std::string& path, long long lo,
              long long hi, long long& out) {
  const std::optional<std::string> text = plain_scalar(log, node, path, "an integer");
  if (!text) return false;
  std::string_view digits = *text;
  if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
  long long value = 0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (error != std::errc() || end != digits.data() + digits.size()) {
    log.add(node.Mark(), path, "expected an integer, got " + describe(node));
    return false;
  }
  if (value < lo || value > hi) {
    log.add(node.Mark(), path,
            "value " + *text + " is out of range; valid: [" + std::to_string(lo) + ", " +
                std::to_string(hi) + "]");
    return false;
  }
  out = value;
  return true;
}

bool read_string(IssueLog& log, const YAML::Node& node, const std::string& path, std::string& out) {
  if (!node.IsDefined() || !node.IsScalar()) {
    log.add(node.Mark(), path, "expected text, got " + describe(node));
    return false;
  }
  out = node.Scalar();
  return true;
}

bool read_vec3(IssueLog& log, const YAML::Node& node, const std::string& path, const Range& range,
               Eigen::Vector3d& out) {
  if (!node.IsDefined() || !node.IsSequence() || node.size() != 3) {
    const std::string got =
        node.IsSequence() ? "a sequence of " + std::to_string(node.size()) : describe(node);
    log.add(node.Mark(), path, "expected a sequence of 3 numbers [x, y, z], got " + got);
    return false;
  }
  Eigen::Vector3d value;
  bool ok = true;
  for (std::size_t i = 0; i < 3; ++i) {
    const std::string item_path = path + "[" + std::to_string(i) + "]";
    ok = read_double(log, node[i], item_path, range, value[static_cast<Eigen::Index>(i)]) && ok;
  }
  if (ok) out = value;
  return ok;
}

MapReader::MapReader(IssueLog& log, const YAML::Node& node, std::string path,
                     std::initializer_list<std::string_view> valid_keys)
    : log_(&log), path_(std::move(path)), mark_(node.Mark()) {
  if (!node.IsDefined() || !node.IsMap()) {
    log.add(node.Mark(), path_.empty() ? "(top level)" : path_,
            "expected a mapping (key: value lines), got " + describe(node));
    return;
  }
  is_map_ = true;
  for (auto it = node.begin(); it != node.end(); ++it) {
    if (!it->first.IsScalar()) {
      log.add(it->first.Mark(), path_, "a key must be plain text, got " + describe(it->first));
      continue;
    }
    entries_.push_back(Entry{it->first.Scalar(), it->first, it->second});
  }
  check_keys(std::vector<std::string_view>(valid_keys));
}

void MapReader::check_keys(const std::vector<std::string_view>& valid_keys) {
  std::string listed;
  for (const std::string_view key : valid_keys) {
    if (!listed.empty()) listed += ", ";
    listed += key;
  }
  for (std::size_t i = 0; i < entries_.size(); ++i) {
    const Entry& entry = entries_[i];
    for (std::size_t j = 0; j < i; ++j) {
      if (entries_[j].key == entry.key) {
        log_->add(entry.key_node.Mark(), child_path(entry.key),
                  "duplicate key (first given on line " +
                      std::to_string(one_based(entries_[j].key_node.Mark().line)) + ")");
        break;
      }
    }
    if (std::find(valid_keys.begin(), valid_keys.end(), entry.key) != valid_keys.end()) {
      continue;
    }
    std::string message = "unknown key '" + entry.key + "'";
    if (const std::optional<std::size_t> guess = nearest(entry.key, valid_keys)) {
      message += "; did you mean '" + std::string(valid_keys[*guess]) + "'?";
    } else {
      message += '.';
    }
    message += " Valid keys here: " + listed;
    log_->add(entry.key_node.Mark(), child_path(entry.key), std::move(message));
  }
}

const MapReader::Entry* MapReader::find(std::string_view key) const {
  for (const Entry& entry : entries_) {
    if (entry.key == key) return &entry;
  }
  return nullptr;
}

bool MapReader::has(std::string_view key) const {
  return find(key) != nullptr;
}

YAML::Node MapReader::value(std::string_view key) const {
  const Entry* entry = find(key);
  return entry ? entry->value : YAML::Node(YAML::NodeType::Undefined);
}

YAML::Mark MapReader::key_mark(std::string_view key) const {
  const Entry* entry = find(key);
  return entry ? entry->key_node.Mark() : mark_;
}

std::string MapReader::child_path(std::string_view key) const {
  return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

bool MapReader::require(std::string_view key) const {
  if (has(key)) return true;
  if (is_map_) {
    log_->add(mark_, child_path(key), "missing required key '" + std::string(key) + "'");
  }
  return false;
}

void MapReader::reject(std::string_view key, std::string_view why) const {
  // Built by append: GCC 12 at -O3 reports a false -Wrestrict on
  // "literal" + std::string(view) (GCC bug 105651).
  std::string message = "'";
  message.append(key).append("' is not valid here: ").append(why);
  log_->add(key_mark(key), child_path(key), std::move(message));
}

bool MapReader::read(std::string_view key, const Range& range, double& out) const {
  return has(key) && read_double(*log_, value(key), child_path(key), range, out);
}

bool MapReader::read(std::string_view key, long long lo, long long hi, int& out) const {
  long long wide = 0;
  if (!has(key) || !read_int(*log_, value(key), child_path(key), lo, hi, wide)) return false;
  out = static_cast<int>(wide);  // lo and hi are within int for every caller
  return true;
}

bool MapReader::read(std::string_view key, bool& out) const {
  if (!has(key)) return false;
  const YAML::Node node = value(key);
  const std::optional<std::string> text =
      plain_scalar(*log_, node, child_path(key), "true or false");
  if (!text) return false;
  if (*text == "true" || *text == "True" || *text == "TRUE") {
    out = true;
    return true;
  }
  if (*text == "false" || *text == "False" || *text == "FALSE") {
    out = false;
    return true;
  }
  log_->add(node.Mark(), child_path(key), "expected true or false, got " + describe(node));
  return false;
}

bool MapReader::read(std::string_view key, std::string& out) const {
  return has(key) && read_string(*log_, value(key), child_path(key), out);
}

bool MapReader::read(std::string_view key, const Range& range, Eigen::Vector3d& out) const {
  return has(key) && read_vec3(*log_, value(key), child_path(key), range, out);
}

bool MapReader::read_ms(std::string_view key, const Range& range_ms,
                        std::chrono::nanoseconds& out) const {
  double ms = 0.0;
  if (!read(key, range_ms, ms)) return false;
  out = std::chrono::nanoseconds(std::llround(ms * 1.0e6));
  return true;
}

bool MapReader::read_s(std::string_view key, const Range& range_s,
                       std::chrono::nanoseconds& out) const {
  double s = 0.0;
  if (!read(key, range_s, s)) return false;
  out = std::chrono::nanoseconds(std::llround(s * 1.0e9));
  return true;
}

}  // namespace fahr::scene::detail
