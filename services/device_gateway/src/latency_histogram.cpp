// Fixed-bin duration histogram and the pose publish-time ring.
#include "fahr/device/latency_histogram.h"

#include <algorithm>
#include <cmath>

namespace fahr::device {

LatencyHistogram::LatencyHistogram(std::chrono::nanoseconds bin_width) : bin_width_(bin_width) {}

void LatencyHistogram::record(std::chrono::nanoseconds duration) {
  const std::int64_t ns = std::max<std::int64_t>(duration.count(), 0);
  const auto bin = std::min<std::int64_t>(ns / bin_width_.count(), static_cast<std::int64_t>(kBins - 1));
  ++bins_[static_cast<std::size_t>(bin)];
  ++count_;
  sum_ += std::chrono::nanoseconds(ns);
  max_ = std::max(max_, std::chrono::nanoseconds(ns));
}

void LatencyHistogram::reset() {
  bins_.fill(0);
  count_ = 0;
  sum_ = std::chrono::nanoseconds(0);
  max_ = std::chrono::nanoseconds(0);
}

std::chrono::nanoseconds LatencyHistogram::mean() const {
  if (count_ == 0) return std::chrono::nanoseconds(0);
  return sum_ / static_cast<std::int64_t>(count_);
}

std::chrono::nanoseconds LatencyHistogram::percentile(double q) const {
  if (count_ == 0) return std::chrono::nanoseconds(0);
  const double clamped = std::clamp(q, 0.0, 1.0);
  // Rank of the sample at quantile q, 1-based (nearest-rank definition).
  const auto rank = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(clamped * static_cast<double>(count_))));
  std::uint64_t seen = 0;
  for (std::size_t bin = 0; bin < kBins; ++bin) {
    seen += bins_[bin];
    if (seen >= rank) {
      if (bin == kBins - 1) return max_;
      return std::min(max_, bin_width_ * static_cast<std::int64_t>(bin + 1));
    }
  }
  return max_;
}

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
