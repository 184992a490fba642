// Lockstep: services advance together in simulated time, so a run is
// reproducible bit for bit whatever the load and whichever vendor.
//
// Time is cut into base steps (the fastest rate of the scene, e.g. 1 ms).
// A participant with period n base steps executes at steps k with k % n == 0.
// The coordinator grants step k once every participant has reported all
// steps before k complete. Within step k a participant reads, from each
// producer, the output of the producer's newest step strictly before k
// (producer_step_for), waiting until it has arrived. Outputs are tagged
// with the step that produced them (SampleHeader.sim_step).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "fahr/common/publisher.h"
#include "fahr/common/subscriber.h"

namespace fahr::common {

// The fixed read rule: the newest step s of a producer with period
// `producer_period` (in base steps) with s < consumer_step. Empty for step
// 0, where no producer has output yet and consumers use their initial state.
std::optional<std::uint64_t> producer_step_for(std::uint64_t consumer_step,
                                               std::uint64_t producer_period);

// True if a participant with this period executes at this base step.
inline bool executes_at(std::uint64_t step, std::uint64_t period) {
  return step % period == 0;
}

// 64-bit FNV-1a, for output hashes.
class OutputHash {
 public:
  void add_bytes(const void* data, std::size_t size);
  // Hashes a sample's CDR bytes with the writer stamp (seq, source time,
  // writer id) zeroed: those differ between runs by design.
  template <class T>
  void add(const T& sample);
  std::uint64_t value() const { return value_; }

 private:
  std::uint64_t value_ = 14695981039346656037ULL;
  std::vector<std::uint8_t> scratch_;
};

class LockstepCoordinator {
 public:
  struct Result {
    bool completed = false;
    std::uint64_t steps = 0;
    // Final output hash of each participant, by name.
    std::map<std::string, std::uint64_t> hashes;
  };

  LockstepCoordinator(Participant& participant, std::chrono::nanoseconds base_period);

  // Waits until the named participants have joined, grants steps
  // 0 .. total_steps-1 in order, then tells everyone to stop. Fails (returns
  // completed = false) if a participant makes no progress within
  // `stall_timeout`. `pace` > 0 holds step k back until k base periods /
  // pace of wall time have passed since step 0 (1.0: no faster than real
  // time, for a viewer watching the run); 0 grants as fast as the
  // participants complete. Pacing only delays grants: the outputs, and so
  // the hashes, are the same.
  Result run(const std::vector<std::string>& participants, std::uint64_t total_steps,
             std::chrono::milliseconds stall_timeout, double pace = 0.0);

 private:
  void on_ack(const msg::StepAck& ack);
  void grant(std::uint64_t step, bool stop);

  std::chrono::nanoseconds base_period_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::map<std::string, std::int64_t> completed_;
  std::map<std::string, std::uint64_t> hashes_;
  Publisher<msg::SimClock> clock_;
  Subscriber<msg::StepAck> acks_;
};

class LockstepClient {
 public:
  LockstepClient(Participant& participant, std::string name);

  // Announces the client until the coordinator has seen it (call once,
  // after creating every input and output).
  void join();
  // Blocks until `step` is granted. False if the run stopped before it or
  // nothing was granted within the timeout.
  bool wait_for_grant(std::uint64_t step, std::chrono::milliseconds timeout);
  // Reports every step up to and including `step` complete.
  void complete_through(std::uint64_t step, std::uint64_t output_hash);
  bool stopped() const;
  // Blocks until the coordinator says stop; false after the timeout. A
  // client that leaves after its own last step waits here first: leaving
  // at once can take its last acknowledgement and outputs with it (a
  // reliable writer deleted before the readers acknowledged; seen on Fast
  // DDS as a clock stalled one step before the end).
  bool wait_for_stop(std::chrono::milliseconds timeout);

 private:
  void on_clock(const msg::SimClock& clock);

  std::string name_;
  std::uint32_t id_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::int64_t granted_ = -1;
  bool stop_ = false;
  Publisher<msg::StepAck> acks_;
  Subscriber<msg::SimClock> clock_;
};

// QoS for lockstep outputs: reliable, deep enough for StepInput, and
// transient local: a participant's first outputs may be written before the
// reader in another process has matched its writer (joining only proves
// each side exists), and must still reach it.
template <class T>
QosProfile lockstep_output_qos() {
  QosProfile qos = QosProfile::for_role(TopicTraits<T>::kRole);
  qos.reliability = Reliability::kReliable;
  qos.durability = Durability::kTransientLocal;
  qos.history_depth = 8;
  qos.liveliness_lease = {};
  return qos;
}

// The input of one topic in lockstep: every sample kept by the step that
// produced it (a few steps deep), so a consumer reads exactly the step the
// read rule names even when the producer has already published the next.
template <class T>
class StepInput {
 public:
  static constexpr std::size_t kDepth = 8;

  StepInput(Participant& participant, std::string_view topic_name = TopicTraits<T>::kName)
      : subscriber_(participant, input_qos(), topic_name,
                    [this](const T& sample, const SampleInfo&) { store(sample); }) {}
  // Only the samples `wanted` keeps: one instance of a keyed topic (a
  // body's), whose steps would otherwise share the slots with the others'.
  StepInput(Participant& participant, std::function<bool(const T&)> wanted,
            std::string_view topic_name = TopicTraits<T>::kName)
      : wanted_(std::move(wanted)),
        subscriber_(participant, input_qos(), topic_name,
                    [this](const T& sample, const SampleInfo&) { store(sample); }) {}

  // Blocks until the sample of producer step `step` is here; null on timeout.
  const T* wait(std::uint64_t step, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    const T* found = nullptr;
    changed_.wait_for(lock, timeout, [&] { return (found = find(step)) != nullptr; });
    return found;
  }

 private:
  static QosProfile input_qos() {
    QosProfile qos = lockstep_output_qos<T>();
    qos.history_depth = static_cast<int>(kDepth);
    return qos;
  }
  void store(const T& sample) {
    if (wanted_ && !wanted_(sample)) return;
    {
      std::lock_guard lock(mutex_);
      Slot& slot = slots_[next_++ % kDepth];
      slot.value = sample;
      slot.valid = true;
    }
    changed_.notify_all();
  }
  const T* find(std::uint64_t step) const {
    for (const auto& slot : slots_) {
      if (slot.valid && slot.value.header().sim_step() == step) return &slot.value;
    }
    return nullptr;
  }

  struct Slot {
    T value{};
    bool valid = false;
  };
  std::mutex mutex_;
  std::condition_variable changed_;
  std::array<Slot, kDepth> slots_{};
  std::size_t next_ = 0;
  std::function<bool(const T&)> wanted_;
  Subscriber<T> subscriber_;  // last: delivers into the members above
};

}  // namespace fahr::common
