// Zstandard and LZ4 frames through Debian's libzstd and liblz4.
#include "compression.h"

#include <lz4frame.h>
#include <zstd.h>

#include <cstring>

namespace fahr::mcap::detail {

bool compress(std::string_view algorithm, std::span<const std::uint8_t> in,
              std::vector<std::uint8_t>& out, int level) {
  if (algorithm == "zstd") {
    out.resize(ZSTD_compressBound(in.size()));
    const std::size_t n = ZSTD_compress(out.data(), out.size(), in.data(), in.size(), level);
    if (ZSTD_isError(n) != 0U) return false;
    out.resize(n);
    return true;
  }
  if (algorithm == "lz4") {
    LZ4F_preferences_t prefs;
    std::memset(&prefs, 0, sizeof(prefs));
    prefs.compressionLevel = level;
    prefs.frameInfo.contentSize = in.size();
    out.resize(LZ4F_compressFrameBound(in.size(), &prefs));
    const std::size_t n = LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), &prefs);
    if (LZ4F_isError(n) != 0U) return false;
    out.resize(n);
    return true;
  }
  if (algorithm.empty()) {
    out.assign(in.begin(), in.end());
    return true;
  }
  return false;
}

bool decompress(std::string_view algorithm, std::span<const std::uint8_t> in,
                std::uint64_t uncompressed_size, std::vector<std::uint8_t>& out) {
  out.resize(uncompressed_size);
  if (algorithm.empty()) {
    if (in.size() != uncompressed_size) return false;
    std::memcpy(out.data(), in.data(), in.size());
    return true;
  }
  if (algorithm == "zstd") {
    const std::size_t n = ZSTD_decompress(out.data(), out.size(), in.data(), in.size());
    return ZSTD_isError(n) == 0U && n == uncompressed_size;
  }
  if (algorithm == "lz4") {
    LZ4F_dctx* ctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION)) != 0U) return false;
    std::size_t produced = 0;
    std::size_t consumed = 0;
    bool ok = true;
    while (ok && consumed < in.size()) {
      std::size_t dst = out.size() - produced;
      std::size_t src = in.size() - consumed;
      const std::size_t hint =
          LZ4F_decompress(ctx, out.data() + produced, &dst, in.data() + consumed, &src, nullptr);
      if (LZ4F_isError(hint) != 0U) ok = false;
      produced += dst;
      consumed += src;
      if (hint == 0) break;  // frame complete
      if (dst == 0 && src == 0) ok = false;
    }
    LZ4F_freeDecompressionContext(ctx);
    return ok && produced == uncompressed_size;
  }
  return false;
}

}  // namespace fahr::mcap::detail
