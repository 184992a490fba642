// Clocks with their units in their names. Wall time (CLOCK_REALTIME) stamps
// samples across processes; monotonic time measures periods and latency;
// thread CPU time measures the work of a tick.
#pragma once

#include <chrono>
#include <cstdint>

namespace fahr::common {

using Nanoseconds = std::chrono::nanoseconds;

std::int64_t wall_now_ns();
std::int64_t monotonic_now_ns();
std::int64_t thread_cpu_now_ns();

}  // namespace fahr::common
