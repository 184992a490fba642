// Percentiles and timing for the benchmark tables.
#pragma once

#include <chrono>
#include <ctime>
#include <vector>

namespace fahr::aist_bench {

// Nearest-rank percentile (p in [0, 100]) of a copy of `values`; 0 if empty.
double percentile(std::vector<double> values, double p);

inline double elapsed_us(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start)
      .count();
}

// CPU time of the calling thread, us: unlike wall time it does not count
// the time another process held the core, so it shows the method's own cost
// on a shared machine (it still counts cache misses the other process caused).
inline double thread_cpu_us() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e6 + static_cast<double>(t.tv_nsec) * 1e-3;
}

}  // namespace fahr::aist_bench
