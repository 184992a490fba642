// Percentiles and timing for the benchmark tables.
#pragma once

#include <chrono>
#include <vector>

namespace fahr::aist_bench {

// Nearest-rank percentile (p in [0, 100]) of a copy of `values`; 0 if empty.
double percentile(std::vector<double> values, double p);

inline double elapsed_us(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace fahr::aist_bench
