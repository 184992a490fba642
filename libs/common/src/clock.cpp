// Clock readings through clock_gettime: the one call every clock here shares.
#include "fahr/common/clock.h"

#include <ctime>

namespace fahr::common {
namespace {
std::int64_t read_ns(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}
}  // namespace

std::int64_t wall_now_ns() {
  return read_ns(CLOCK_REALTIME);
}
std::int64_t monotonic_now_ns() {
  return read_ns(CLOCK_MONOTONIC);
}
std::int64_t thread_cpu_now_ns() {
  return read_ns(CLOCK_THREAD_CPUTIME_ID);
}

}  // namespace fahr::common
