// Clock readings through clock_gettime: the one call every clock here shares.
#include "fahr/common/clock.h"

#include <cstdlib>
#include <ctime>

namespace fahr::common {
namespace {
std::int64_t read_ns(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}
// FAHR_TEST_CLOCK_OFFSET_MS, read once: tests only (clock.h).
std::int64_t test_offset_ns() {
  static const std::int64_t offset = [] {
    const char* text = std::getenv("FAHR_TEST_CLOCK_OFFSET_MS");
    if (text == nullptr || *text == '\0') return std::int64_t{0};
    char* end = nullptr;
    const double ms = std::strtod(text, &end);
    return *end == '\0' ? static_cast<std::int64_t>(ms * 1e6) : std::int64_t{0};
  }();
  return offset;
}
}  // namespace

std::int64_t wall_now_ns() {
  return read_ns(CLOCK_REALTIME) + test_offset_ns();
}
std::int64_t monotonic_now_ns() {
  return read_ns(CLOCK_MONOTONIC);
}
std::int64_t thread_cpu_now_ns() {
  return read_ns(CLOCK_THREAD_CPUTIME_ID);
}

}  // namespace fahr::common
