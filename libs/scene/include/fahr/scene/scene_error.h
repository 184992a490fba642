// The error every scene check reports: where (file, line, column, key path)
// and what, so a user can fix the file without reading the loader.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace fahr::scene {

struct SceneIssue {
  std::string file;      // scene file (or display name of parsed text)
  int line = 0;          // 1-based; 0 when unknown
  int column = 0;        // 1-based; 0 when unknown
  std::string key_path;  // e.g. bodies[2].material.poisson_ratio; may be empty
  std::string message;

  // "file:line:column: key_path: message"
  std::string to_string() const;
};

class SceneError : public std::runtime_error {
 public:
  explicit SceneError(std::vector<SceneIssue> issues);
  const std::vector<SceneIssue>& issues() const { return issues_; }

 private:
  std::vector<SceneIssue> issues_;
};

}  // namespace fahr::scene
