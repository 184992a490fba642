// The real-time tick's whole-run figures (see run_report.h).
#include "fahr/haptic_service/run_report.h"

#include <chrono>
#include <cstdio>

namespace fahr::haptic_service {
namespace {

// A period between ticks longer than this is a late answer (the gateway's
// servo loop runs at 1 ms).
constexpr std::int64_t kLongPeriodNs = 1'500'000;

std::chrono::nanoseconds from_us(double us) {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
      std::chrono::duration<double, std::micro>(us));
}

double us(std::chrono::nanoseconds d) {
  return static_cast<double>(d.count()) / 1e3;
}

void print_part(const char* name, const metrics::DurationHistogram& h) {
  std::printf("fahr_haptic_service: tick part %-22s us median %.0f p99 %.0f p99.9 %.0f max %.0f\n",
              name, us(h.percentile(0.5)), us(h.percentile(0.99)), us(h.percentile(0.999)),
              us(h.max()));
}

}  // namespace

void RunReport::record(std::int64_t t0, std::int64_t c0, std::int64_t c1, std::int64_t c2,
                       const TickPhases& phases) {
  work_cpu_.record(std::chrono::nanoseconds(c1 - c0));
  publish_cpu_.record(std::chrono::nanoseconds(c2 - c1));
  query_wall_.record(from_us(phases.tissue_query_us));
  response_wall_.record(from_us(phases.response_us));
  tick_cpu_.record(std::chrono::nanoseconds(c2 - c0));
  if (previous_start_ns_ != 0 && t0 - previous_start_ns_ > kLongPeriodNs) ++long_periods_;
  previous_start_ns_ = t0;
}

void RunReport::print(std::uint64_t contact_sets_handed, std::uint64_t contact_sets_written,
                      std::uint64_t contact_sets_refused, const FeedMetrics& feed) const {
  std::printf(
      "fahr_haptic_service: ContactSets handed over %llu, written %llu, refused %llu (the rest "
      "superseded "
      "before their write)\n",
      static_cast<unsigned long long>(contact_sets_handed),
      static_cast<unsigned long long>(contact_sets_written),
      static_cast<unsigned long long>(contact_sets_refused));
  std::printf(
      "fahr_haptic_service: %llu FEM states digested (%llu refused), worst digest %.0f us\n",
      static_cast<unsigned long long>(feed.fem_states.load()),
      static_cast<unsigned long long>(feed.bad_states.load()), feed.digest_us_peak.load());
  std::printf(
      "fahr_haptic_service: tick CPU us median %.0f p99 %.0f p99.9 %.0f max %.0f over %llu ticks; "
      "periods > 1.5 ms: %llu\n",
      us(tick_cpu_.percentile(0.5)), us(tick_cpu_.percentile(0.99)),
      us(tick_cpu_.percentile(0.999)), us(tick_cpu_.max()),
      static_cast<unsigned long long>(tick_cpu_.count()),
      static_cast<unsigned long long>(long_periods_));
  print_part("work (thread CPU)", work_cpu_);
  print_part("publishing (thread CPU)", publish_cpu_);
  print_part("tissue query (wall)", query_wall_);
  print_part("response (wall)", response_wall_);
}

}  // namespace fahr::haptic_service
