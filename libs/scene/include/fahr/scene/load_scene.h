// Reading a scene file: every key checked (type, range, unknown keys with the
// valid ones listed), every cross reference resolved, errors collected.
#pragma once

#include <filesystem>
#include <memory>
#include <string_view>

#include "fahr/scene/scene.h"

namespace fahr::scene {

struct LoadOptions {
  // Check that mesh, fixed-node and replay files exist, and read the
  // fixed-node files. Off for scenes whose meshes are not generated yet.
  bool check_files = true;
};

// Reads and checks the scene at path. Throws SceneError (naming the file,
// line, column and key of each problem) when the scene is invalid.
std::shared_ptr<const Scene> load_scene(const std::filesystem::path& path,
                                        const LoadOptions& options = {});

// As load_scene, from text: display_name stands for the file in messages and
// relative paths are resolved against base_dir.
std::shared_ptr<const Scene> parse_scene(std::string_view text, std::string_view display_name,
                                         const std::filesystem::path& base_dir,
                                         const LoadOptions& options = {});

}  // namespace fahr::scene
