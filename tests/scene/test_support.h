// Helpers shared by the scene tests: temporary folders, a minimal valid
// scene to vary, and parsing that returns the error message.
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "fahr/scene/load_scene.h"

namespace fahr::scene::test {

// A fresh folder under the system temp dir, removed with its contents.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  // Writes text to path()/relative (creating folders) and returns the path.
  std::filesystem::path write(const std::filesystem::path& relative, std::string_view text) const;

 private:
  std::filesystem::path path_;
};

// The repository's deployment/scenes folder.
std::filesystem::path scenes_dir();
std::string read_text(const std::filesystem::path& path);

// Parses without touching files (check_files off), as "test.yaml" in /scene.
std::shared_ptr<const Scene> parse(std::string_view text);

// Parses text that must fail; returns the SceneError message, or "" (and a
// test failure) when it parsed.
std::string error_of(std::string_view text, const LoadOptions& options = {false});

// A deformable tongue, a tool, two obstacles and a device: the smallest scene
// with every role. Tests append to it or replace lines in it.
inline constexpr std::string_view kMinimalScene = R"(format_version: 1
name: minimal
bodies:
  - name: tongue
    role: deformable
    mesh: tongue.node
    unit: mm
  - name: blade
    role: tool
    mesh: blade.obj
    unit: mm
  - name: palate
    role: obstacle
    mesh: palate.obj
    unit: cm
  - name: jaw
    role: obstacle
    mesh: jaw.stl
    unit: m
device:
  backend: simulated
)";

// kMinimalScene with the first occurrence of `from` replaced by `to`.
std::string replaced(std::string_view from, std::string_view to);

}  // namespace fahr::scene::test
