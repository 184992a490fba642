// The fixed-node file format: one non-negative node index per line; blank
// lines and '#' comments (whole line or after the index) are ignored.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace fahr::scene {

// Reads the file and returns zero-based indices, sorted and unique; index_base
// (0 or 1) is subtracted from each. Throws SceneError naming the file and line
// of the first bad entry, or the file when it cannot be read.
std::vector<std::uint32_t> read_node_index_file(const std::filesystem::path& path, int index_base);

}  // namespace fahr::scene
