#include "fahr/scene/scene_error.h"

#include <utility>

namespace fahr::scene {

namespace {

std::string join(const std::vector<SceneIssue>& issues) {
  std::string out;
  if (issues.size() > 1) {
    out = std::to_string(issues.size()) + " problems in the scene:\n";
  }
  for (std::size_t i = 0; i < issues.size(); ++i) {
    if (i > 0) out += '\n';
    out += issues[i].to_string();
  }
  return out;
}

}  // namespace

std::string SceneIssue::to_string() const {
  std::string out = file;
  if (line > 0) {
    out += ':' + std::to_string(line);
    if (column > 0) out += ':' + std::to_string(column);
  }
  out += ": ";
  if (!key_path.empty()) out += key_path + ": ";
  out += message;
  return out;
}

SceneError::SceneError(std::vector<SceneIssue> issues)
    : std::runtime_error(join(issues)), issues_(std::move(issues)) {}

}  // namespace fahr::scene
