// Per-sample metadata, the same for every vendor.
#pragma once

#include <cstdint>

namespace fahr::common {

struct SampleInfo {
  // Writer sequence number and identity from the sample's SampleHeader.
  std::uint64_t seq = 0;
  std::uint32_t writer_id = 0;
  // DDS source timestamp (the writer's wall clock at write), ns since epoch.
  std::int64_t source_time_ns = 0;
  // Reader's wall clock when the sample reached fahr, ns since epoch.
  std::int64_t receive_time_ns = 0;
  // Samples of this writer that never arrived before this one (seq gap).
  std::uint64_t missed_before = 0;
  // The DDS writer it came from (backend.h SampleSink): chosen by the
  // middleware, not by the writer.
  std::uint64_t source_key = 0;
};

}  // namespace fahr::common
