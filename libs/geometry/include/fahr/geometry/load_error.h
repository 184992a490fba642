// The error every mesh loader throws: it names the file, the line (when the
// format has lines) and what was wrong, so a user can fix the file at once.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace fahr::geometry {

class LoadError : public std::runtime_error {
 public:
  // line is 1-based; 0 means the format has no line (binary, or a whole-file problem).
  LoadError(std::string_view file, int line, std::string_view message);

  const std::string& file() const { return file_; }
  int line() const { return line_; }

 private:
  std::string file_;
  int line_ = 0;
};

}  // namespace fahr::geometry
