#include "test_support.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "fahr/scene/scene_error.h"

namespace fahr::scene::test {

TempDir::TempDir() {
  std::string pattern = (std::filesystem::temp_directory_path() / "fahr_scene_XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  path_ = pattern;
}

TempDir::~TempDir() {
  std::error_code ignored;  // a leftover temp folder is not worth a crash
  std::filesystem::remove_all(path_, ignored);
}

std::filesystem::path TempDir::write(const std::filesystem::path& relative,
                                     std::string_view text) const {
  const std::filesystem::path file = path_ / relative;
  std::filesystem::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary);
  out << text;
  return file;
}

std::filesystem::path scenes_dir() {
  return std::filesystem::path(FAHR_SOURCE_DIR) / "deployment" / "scenes";
}

std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::shared_ptr<const Scene> parse(std::string_view text) {
  return parse_scene(text, "test.yaml", "/scene", LoadOptions{false});
}

std::string error_of(std::string_view text, const LoadOptions& options) {
  try {
    parse_scene(text, "test.yaml", "/scene", options);
  } catch (const SceneError& error) {
    return error.what();
  }
  ADD_FAILURE() << "expected a SceneError for:\n" << text;
  return "";
}

std::string replaced(std::string_view from, std::string_view to) {
  std::string text(kMinimalScene);
  const std::size_t at = text.find(from);
  if (at == std::string::npos) {
    ADD_FAILURE() << "'" << from << "' is not in the minimal scene";
    return text;
  }
  text.replace(at, from.size(), to);
  return text;
}

}  // namespace fahr::scene::test
