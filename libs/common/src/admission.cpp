// Status metrics of a Subscriber's Admission (see subscriber.h).
#include <string>
#include <utility>
#include <vector>

#include "fahr/common/subscriber.h"

namespace fahr::common {

void append_admission_metrics(const AdmissionCounts& counts, const std::string& prefix,
                              std::vector<std::pair<std::string, double>>& out) {
  const auto get = [](const std::atomic<std::uint64_t>& a) {
    return static_cast<double>(a.load(std::memory_order_relaxed));
  };
  out.emplace_back(prefix + "_refused_foreign", get(counts.foreign));
  out.emplace_back(prefix + "_refused_order", get(counts.out_of_order));
  out.emplace_back(prefix + "_refused_invalid", get(counts.invalid));
}

std::string admission_summary(const AdmissionCounts& counts) {
  return "foreign " + std::to_string(counts.foreign.load(std::memory_order_relaxed)) +
         ", out of order " + std::to_string(counts.out_of_order.load(std::memory_order_relaxed)) +
         ", invalid " + std::to_string(counts.invalid.load(std::memory_order_relaxed)) +
         ", source changes " +
         std::to_string(counts.source_changes.load(std::memory_order_relaxed));
}

}  // namespace fahr::common
