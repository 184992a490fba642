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

}  // namespace fahr::common
