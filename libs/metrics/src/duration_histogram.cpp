// Fixed-bin duration histogram (see duration_histogram.h).
#include "fahr/metrics/duration_histogram.h"

#include <algorithm>
#include <cmath>

namespace fahr::metrics {

DurationHistogram::DurationHistogram(std::chrono::nanoseconds bin_width) : bin_width_(bin_width) {}

void DurationHistogram::record(std::chrono::nanoseconds duration) {
  const std::int64_t ns = std::max<std::int64_t>(duration.count(), 0);
  const auto bin =
      std::min<std::int64_t>(ns / bin_width_.count(), static_cast<std::int64_t>(kBins - 1));
  ++bins_[static_cast<std::size_t>(bin)];
  ++count_;
  sum_ += std::chrono::nanoseconds(ns);
  max_ = std::max(max_, std::chrono::nanoseconds(ns));
}

void DurationHistogram::reset() {
  bins_.fill(0);
  count_ = 0;
  sum_ = std::chrono::nanoseconds(0);
  max_ = std::chrono::nanoseconds(0);
}

std::chrono::nanoseconds DurationHistogram::mean() const {
  if (count_ == 0) return std::chrono::nanoseconds(0);
  return sum_ / static_cast<std::int64_t>(count_);
}

std::chrono::nanoseconds DurationHistogram::percentile(double q) const {
  if (count_ == 0) return std::chrono::nanoseconds(0);
  const double clamped = std::clamp(q, 0.0, 1.0);
  // Rank of the sample at quantile q, 1-based (nearest-rank definition).
  const auto rank = std::max<std::uint64_t>(
      1, static_cast<std::uint64_t>(std::ceil(clamped * static_cast<double>(count_))));
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

}  // namespace fahr::metrics
