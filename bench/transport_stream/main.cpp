// fahr_transport_stream: the station's four streams at their rates between
// three processes, with none of the services' computation, so the transport
// alone is measured on a vendor mix:
//
//   gateway: writes DevicePose at 1 kHz, reads ForceCommand
//   haptic:  reads DevicePose and DeformationState, writes ForceCommand and a
//            ContactSet at 1 kHz
//   fem:     writes a DeformationState of --state-kb KiB at --state-hz,
//            reads ContactSet
//
//   fahr_transport_stream --role gateway|haptic|fem [--dds V] [--domain N]
//       [--dds-profile F] [--seconds S] [--state-kb K] [--state-hz R] [--contacts N]
//
// Each process waits until its readers and writers are matched (at most
// 10 s), runs for --seconds, then prints one line per topic it reads:
// samples, sequence gaps, rate, one-way latency (the writer's stamp to the
// reader's clock, one host) and the longest gap between arrivals.
#include <time.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "fahr/cli/cli.h"
#include "fahr/common/clock.h"
#include "fahr/common/participant.h"
#include "fahr/common/publisher.h"
#include "fahr/common/stop_signal.h"
#include "fahr/common/subscriber.h"
#include "fahr/common/transport_config.h"

namespace fahr::bench {
namespace {

using namespace std::chrono_literals;

// Arrival statistics of one topic, filled on the vendor's thread.
class Arrivals {
 public:
  explicit Arrivals(std::string name) : name_(std::move(name)) { latencies_ms_.reserve(1 << 20); }
  void arrived(std::int64_t source_ns, std::uint64_t missed_before) {
    const std::int64_t now = common::wall_now_ns();
    std::lock_guard lock(mutex_);
    if (!started_) return;
    latencies_ms_.push_back(static_cast<double>(now - source_ns) * 1e-6);
    if (last_ns_ != 0)
      max_gap_ms_ = std::max(max_gap_ms_, static_cast<double>(now - last_ns_) * 1e-6);
    last_ns_ = now;
    missed_ += missed_before;
  }
  void start() {
    std::lock_guard lock(mutex_);
    started_ = true;
  }
  void print(double seconds) {
    std::lock_guard lock(mutex_);
    auto sorted = latencies_ms_;
    std::sort(sorted.begin(), sorted.end());
    auto at = [&](double q) {
      return sorted.empty()
                 ? 0.0
                 : sorted[std::min(sorted.size() - 1, static_cast<std::size_t>(
                                                          q * static_cast<double>(sorted.size())))];
    };
    std::printf(
        "stream: %-18s samples %7zu gaps %6llu rate %7.1f Hz latency ms p50 %7.3f p99 %8.3f max "
        "%8.3f longest gap %8.3f ms\n",
        name_.c_str(), sorted.size(), static_cast<unsigned long long>(missed_),
        static_cast<double>(sorted.size()) / seconds, at(0.5), at(0.99),
        sorted.empty() ? 0.0 : sorted.back(), max_gap_ms_);
  }

 private:
  std::string name_;
  std::mutex mutex_;
  bool started_ = false;
  std::vector<double> latencies_ms_;
  std::int64_t last_ns_ = 0;
  double max_gap_ms_ = 0;
  std::uint64_t missed_ = 0;
};

template <class T>
typename common::Subscriber<T>::Handler count_into(Arrivals& arrivals) {
  return [&arrivals](const T& sample, const common::SampleInfo& info) {
    arrivals.arrived(sample.header().source_time_ns(), info.missed_before);
  };
}

template <class T>
common::QosProfile qos_of() {
  return common::QosProfile::for_role(common::TopicTraits<T>::kRole);
}

// Sleeps until `next` (CLOCK_MONOTONIC), then moves it on by `period`.
void sleep_period(timespec& next, std::int64_t period_ns) {
  next.tv_nsec += period_ns;
  while (next.tv_nsec >= 1'000'000'000) {
    next.tv_nsec -= 1'000'000'000;
    ++next.tv_sec;
  }
  clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr);
}

// Runs `tick` at `hz` until `stop` is set.
template <class Tick>
void run_at(double hz, const std::atomic<bool>& stop, Tick tick) {
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  const auto period_ns = static_cast<std::int64_t>(1e9 / hz);
  while (!stop.load()) {
    tick();
    sleep_period(next, period_ns);
  }
}

bool wait_matched(const std::vector<std::function<int()>>& counts, std::chrono::seconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < until) {
    if (std::all_of(counts.begin(), counts.end(), [](const auto& c) { return c() > 0; }))
      return true;
    std::this_thread::sleep_for(10ms);
  }
  return false;
}

// Waits for the matches, runs `loop` on a thread for `seconds`, prints the
// arrivals. The exit status of the process.
int measure(const std::string& role, double seconds,
            const std::vector<std::function<int()>>& matched,
            const std::vector<Arrivals*>& arrivals,
            const std::function<void(const std::atomic<bool>&)>& loop) {
  if (!wait_matched(matched, std::chrono::seconds(10))) {
    std::fprintf(stderr, "fahr_transport_stream: %s not matched within 10 s\n", role.c_str());
    return 1;
  }
  std::this_thread::sleep_for(500ms);  // the other processes match too
  for (auto* a : arrivals) a->start();
  const auto started = std::chrono::steady_clock::now();
  std::atomic<bool> stop{false};
  std::thread thread([&] { loop(stop); });
  while (!common::stop_requested() &&
         std::chrono::steady_clock::now() - started < std::chrono::duration<double>(seconds)) {
    std::this_thread::sleep_for(50ms);
  }
  stop.store(true);
  thread.join();
  const double ran =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  for (auto* a : arrivals) a->print(ran);
  return 0;
}

}  // namespace
}  // namespace fahr::bench

int main(int argc, char** argv) {
  using namespace fahr;
  using namespace fahr::bench;
  fahr::cli::App app{"fahr_transport_stream: the station's streams at their rates"};
  std::string role;
  std::string dds;
  std::string domain;
  std::string profile;
  double seconds = 10;
  double state_kb = 100;
  double state_hz = 200;
  int contacts = 40;
  app.add_option("--role", role, "gateway, haptic or fem")->required();
  app.add_option("--dds", dds, "fastdds or cyclonedds (default $FAHR_DDS)");
  app.add_option("--domain", domain, "DDS domain (default $FAHR_DOMAIN_ID)");
  app.add_option("--dds-profile", profile, "vendor XML configuration");
  app.add_option("--seconds", seconds, "measured run time");
  app.add_option("--state-kb", state_kb, "DeformationState size, KiB");
  app.add_option("--state-hz", state_hz, "DeformationState rate");
  app.add_option("--contacts", contacts, "contacts per ContactSet");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  if (role != "gateway" && role != "haptic" && role != "fem") {
    std::fprintf(stderr, "fahr_transport_stream: --role must be gateway, haptic or fem\n");
    return 2;
  }
  common::Participant participant(
      common::transport_config_from(dds, domain, profile, "transport_stream_" + role));
  common::install_stop_handlers();
  if (role == "gateway") {
    Arrivals forces("ForceCommand");
    common::Publisher<msg::DevicePose> pose_pub(participant);
    common::Subscriber<msg::ForceCommand> force_sub(participant, qos_of<msg::ForceCommand>(),
                                                    common::TopicTraits<msg::ForceCommand>::kName,
                                                    count_into<msg::ForceCommand>(forces));
    return measure(
        role, seconds,
        {[&] { return pose_pub.matched_readers(); }, [&] { return force_sub.matched_writers(); }},
        {&forces}, [&](const std::atomic<bool>& stop) {
          msg::DevicePose pose;
          std::uint64_t tick = 0;
          run_at(1000, stop, [&] {
            pose.servo_tick(++tick);
            pose_pub.write(pose);
          });
        });
  }
  if (role == "haptic") {
    Arrivals poses("DevicePose");
    Arrivals states("DeformationState");
    common::Publisher<msg::ForceCommand> force_pub(participant);
    common::Publisher<msg::ContactSet> contact_pub(participant);
    common::Subscriber<msg::DevicePose> pose_sub(participant, qos_of<msg::DevicePose>(),
                                                 common::TopicTraits<msg::DevicePose>::kName,
                                                 count_into<msg::DevicePose>(poses));
    common::Subscriber<msg::DeformationState> state_sub(
        participant, qos_of<msg::DeformationState>(),
        common::TopicTraits<msg::DeformationState>::kName,
        count_into<msg::DeformationState>(states));
    return measure(
        role, seconds,
        {[&] { return force_pub.matched_readers(); }, [&] { return contact_pub.matched_readers(); },
         [&] { return pose_sub.matched_writers(); }, [&] { return state_sub.matched_writers(); }},
        {&poses, &states}, [&](const std::atomic<bool>& stop) {
          msg::ForceCommand force;
          msg::ContactSet contact_set;
          contact_set.contacts().resize(static_cast<std::size_t>(contacts));
          run_at(1000, stop, [&] {
            force_pub.write(force);
            contact_pub.write(contact_set);
          });
        });
  }
  Arrivals contact_sets("ContactSet");
  common::Publisher<msg::DeformationState> state_pub(participant);
  common::Subscriber<msg::ContactSet> contact_sub(participant, qos_of<msg::ContactSet>(),
                                                  common::TopicTraits<msg::ContactSet>::kName,
                                                  count_into<msg::ContactSet>(contact_sets));
  return measure(
      role, seconds,
      {[&] { return state_pub.matched_readers(); }, [&] { return contact_sub.matched_writers(); }},
      {&contact_sets}, [&](const std::atomic<bool>& stop) {
        msg::DeformationState state;
        // 1,339 nodes' positions and velocities, the rest as compliance.
        state.positions_m().assign(4017, 0.1F);
        state.velocities_mps().assign(4017, 0.0F);
        const auto rest =
            static_cast<std::size_t>(std::max(0.0, state_kb * 1024.0 - 2.0 * 4017 * 4) / 4.0);
        state.compliance_mpn().assign(std::min<std::size_t>(rest, msg::MAX_COMPLIANCE_ENTRIES),
                                      1e-4F);
        std::uint64_t step = 0;
        run_at(state_hz, stop, [&] {
          state.step(++step);
          state_pub.write(state);
        });
      });
}
