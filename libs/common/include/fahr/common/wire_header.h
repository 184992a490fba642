// What the recorder and the visualizer read from a sample's bytes without
// decoding it: the
// encapsulation, the SampleHeader every fahr type starts with, and the key
// that follows it in keyed types (idl/fahr/common.idl). XCDR1 offsets count
// from after the 4-byte encapsulation header.
#pragma once

#include <cstdint>
#include <optional>
#include <span>

namespace fahr::common {

struct WireHeader {
  std::uint64_t seq = 0;
  std::int64_t source_time_ns = 0;
  std::int64_t sim_time_ns = 0;
  std::uint32_t writer_id = 0;
  std::uint32_t key = 0;  // keyed types only
};

// nullopt if the bytes are too short or not plain CDR (XCDR1, either byte order).
std::optional<WireHeader> read_wire_header(std::span<const std::uint8_t> cdr, bool keyed);

}  // namespace fahr::common
