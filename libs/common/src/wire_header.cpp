// SampleHeader fields at their XCDR1 offsets: seq 0, source_time_ns 8,
// sim_time_ns 16, sim_step 24, writer_id 32; a key right after, at 36.
#include "fahr/common/wire_header.h"

namespace fahr::common {
namespace {

constexpr std::size_t kEncapsulation = 4;

std::uint64_t load(std::span<const std::uint8_t> b, std::size_t at, int size, bool little) {
  std::uint64_t v = 0;
  for (int i = 0; i < size; ++i) {
    const std::uint64_t byte = b[at + static_cast<std::size_t>(i)];
    v |= little ? byte << (8 * i) : byte << (8 * (size - 1 - i));
  }
  return v;
}

}  // namespace

std::optional<WireHeader> read_wire_header(std::span<const std::uint8_t> cdr, bool keyed) {
  const std::size_t need = kEncapsulation + (keyed ? 40 : 36);
  // Representation identifier 0x0000 CDR_BE or 0x0001 CDR_LE (plain XCDR1).
  if (cdr.size() < need || cdr[0] != 0 || cdr[1] > 1) return std::nullopt;
  const bool little = cdr[1] == 1;
  WireHeader h;
  h.seq = load(cdr, kEncapsulation + 0, 8, little);
  h.source_time_ns = static_cast<std::int64_t>(load(cdr, kEncapsulation + 8, 8, little));
  h.sim_time_ns = static_cast<std::int64_t>(load(cdr, kEncapsulation + 16, 8, little));
  h.writer_id = static_cast<std::uint32_t>(load(cdr, kEncapsulation + 32, 4, little));
  if (keyed) h.key = static_cast<std::uint32_t>(load(cdr, kEncapsulation + 36, 4, little));
  return h;
}

}  // namespace fahr::common
