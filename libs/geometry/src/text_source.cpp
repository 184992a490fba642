// Whole-file reads for the text loaders.
#include "fahr/geometry/text_source.h"

#include <fstream>
#include <sstream>

#include "fahr/geometry/load_error.h"

namespace fahr::geometry {

std::string read_text_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw LoadError(path, 0, "cannot open file");
  }
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) {
    throw LoadError(path, 0, "read error");
  }
  return std::move(buffer).str();
}

}  // namespace fahr::geometry
