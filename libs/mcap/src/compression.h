// Chunk compression: MCAP's "zstd" (a Zstandard frame) and "lz4" (an LZ4
// frame), or none ("").
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace fahr::mcap::detail {

// Compresses `in` into `out` (replacing its content). Returns false for an
// unknown algorithm or a library error.
bool compress(std::string_view algorithm, std::span<const std::uint8_t> in,
              std::vector<std::uint8_t>& out, int level);
// Decompresses into `out`, which must come out exactly `uncompressed_size` long.
bool decompress(std::string_view algorithm, std::span<const std::uint8_t> in,
                std::uint64_t uncompressed_size, std::vector<std::uint8_t>& out);

}  // namespace fahr::mcap::detail
