// Writes 8-bit RGB images as PNG (zlib from Debian's zlib1g-dev for deflate and CRC).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace fahr::scene_render {

// `rgb` holds width * height * 3 bytes, rows top to bottom.
bool write_png(const std::string& path, int width, int height, const std::vector<uint8_t>& rgb,
               std::string& error);

}  // namespace fahr::scene_render
