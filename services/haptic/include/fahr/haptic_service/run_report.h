// Whole-run figures of the haptic service's real-time tick, printed at the
// end of the run (the status windows of ServiceStatus hold 250 ms each):
// the tick's thread-CPU time (the work, whatever the scheduler does), its
// parts, and the wall periods between ticks longer than 1.5 ms (late
// answers). record() allocates nothing: the histograms are sized at
// construction.
#pragma once

#include <cstdint>

#include "fahr/haptic_service/haptic_loop.h"
#include "fahr/haptic_service/tissue_feed.h"
#include "fahr/metrics/duration_histogram.h"

namespace fahr::haptic_service {

class RunReport {
 public:
  // One tick: thread-CPU time at its start (c0), after the loop's work (c1)
  // and after the two DDS writes (c2), ns; its wall start (t0, monotonic,
  // ns); the phases the loop timed.
  void record(std::int64_t t0, std::int64_t c0, std::int64_t c1, std::int64_t c2,
              const TickPhases& phases);

  // The run's last lines: the ContactSets' background writer, the FEM
  // states the feed digested, the tick and its parts.
  void print(std::uint64_t contact_sets_handed, std::uint64_t contact_sets_written,
             std::uint64_t contact_sets_refused, const FeedMetrics& feed) const;

 private:
  metrics::DurationHistogram tick_cpu_{std::chrono::microseconds(5)};  // 5 us bins span 10 ms
  // Its parts: the loop's work (query, solve, the messages filled) and the
  // two DDS writes, thread CPU; the tissue query and the response, wall.
  metrics::DurationHistogram work_cpu_{std::chrono::microseconds(5)};
  metrics::DurationHistogram publish_cpu_{std::chrono::microseconds(5)};
  metrics::DurationHistogram query_wall_{std::chrono::microseconds(5)};
  metrics::DurationHistogram response_wall_{std::chrono::microseconds(5)};
  std::uint64_t long_periods_ = 0;
  std::int64_t previous_start_ns_ = 0;
};

}  // namespace fahr::haptic_service
