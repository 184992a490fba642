// The pose publish-time ring.
#include "fahr/device/latency_histogram.h"

#include <algorithm>
#include <cmath>

namespace fahr::device {

void PoseTimeRing::record(std::uint64_t seq, std::chrono::nanoseconds time) {
  Entry& entry = entries_[seq % kCapacity];
  entry.seq = seq;
  entry.time = time;
}

bool PoseTimeRing::find(std::uint64_t seq, std::chrono::nanoseconds& time) const {
  const Entry& entry = entries_[seq % kCapacity];
  if (seq == 0 || entry.seq != seq) return false;
  time = entry.time;
  return true;
}

}  // namespace fahr::device
