// Fixed-size histogram of durations, cheap enough to fill from a 1 kHz tick:
// record() is an index computation and two additions, nothing allocates.
// Percentiles are read between windows (status reports, a few Hz, or at the
// end of a run) and are the upper edge of their bin, so they over-report by
// at most one bin width. Used for the gateway's motion-to-force latency and
// the haptic service's tick times.
#pragma once

#include <array>
#include <chrono>
#include <cstdint>

namespace fahr::metrics {

class DurationHistogram {
 public:
  static constexpr std::size_t kBins = 2048;

  // `bin_width`: resolution, > 0. The last bin collects everything at or
  // beyond (kBins - 1) * bin_width. 10 us bins span 20 ms: every DDS
  // latency this project measured, with room for spikes.
  explicit DurationHistogram(std::chrono::nanoseconds bin_width);
  DurationHistogram() : DurationHistogram(std::chrono::microseconds(10)) {}

  void record(std::chrono::nanoseconds duration);
  void reset();

  std::uint64_t count() const { return count_; }
  std::chrono::nanoseconds max() const { return max_; }
  std::chrono::nanoseconds mean() const;
  // Duration below which a fraction `q` (in [0, 1]) of the samples lie.
  std::chrono::nanoseconds percentile(double q) const;
  std::uint64_t overflow() const { return bins_[kBins - 1]; }

 private:
  std::chrono::nanoseconds bin_width_;
  std::array<std::uint32_t, kBins> bins_{};
  std::uint64_t count_ = 0;
  std::chrono::nanoseconds sum_{0};
  std::chrono::nanoseconds max_{0};
};

}  // namespace fahr::metrics
