// Clocks with their units in their names. Wall time (CLOCK_REALTIME) stamps
// samples across processes; monotonic time measures periods and latency;
// thread CPU time measures the work of a tick.
#pragma once

#include <chrono>
#include <cstdint>

namespace fahr::common {

using Nanoseconds = std::chrono::nanoseconds;

// Test hook, for tests only: FAHR_TEST_CLOCK_OFFSET_MS (a number of ms,
// read once per process) is added to every wall_now_ns() reading, so a
// test can give one network namespace's processes a wrong clock (as an
// unsynchronised host has) and check that cross-host figures stay honest
// (tests/lab/clock_offset.sh). Never set in a deployment.
std::int64_t wall_now_ns();
std::int64_t monotonic_now_ns();
std::int64_t thread_cpu_now_ns();

}  // namespace fahr::common
