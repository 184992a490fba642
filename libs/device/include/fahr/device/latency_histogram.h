// Motion-to-force latency: the histogram (fahr::metrics) and the ring of
// pose publish times that pairs a ForceCommand with the pose it answers.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>

#include "fahr/metrics/duration_histogram.h"

namespace fahr::device {

// The duration histogram lives in fahr::metrics (the haptic service uses it
// too); the gateway's name for it.
using LatencyHistogram = metrics::DurationHistogram;

// When each recent DevicePose was published, by seq, so a ForceCommand's
// echoed answered_pose_seq gives its motion-to-force latency. A ring of
// fixed size: poses older than kCapacity ticks are forgotten (and such a
// command is stale anyway).
class PoseTimeRing {
 public:
  static constexpr std::size_t kCapacity = 1024;

  void record(std::uint64_t seq, std::chrono::nanoseconds time);
  // True and the time if `seq` is still held.
  bool find(std::uint64_t seq, std::chrono::nanoseconds& time) const;

 private:
  struct Entry {
    std::uint64_t seq = 0;
    std::chrono::nanoseconds time{0};
  };
  std::array<Entry, kCapacity> entries_{};
};

}  // namespace fahr::device
