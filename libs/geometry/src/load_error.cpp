// LoadError: "file:line: message", the form compilers use, so editors can jump to it.
#include "fahr/geometry/load_error.h"

namespace fahr::geometry {
namespace {

std::string format_message(std::string_view file, int line, std::string_view message) {
  std::string text(file);
  if (line > 0) {
    text += ':';
    text += std::to_string(line);
  }
  text += ": ";
  text += message;
  return text;
}

}  // namespace

LoadError::LoadError(std::string_view file, int line, std::string_view message)
    : std::runtime_error(format_message(file, line, message)), file_(file), line_(line) {}

}  // namespace fahr::geometry
