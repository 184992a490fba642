// A triple buffer holding the newest sample of a topic: producers (vendor
// threads) never wait for the consumer, and the consumer (a 1 kHz loop)
// takes the newest sample without locking or allocating.
//
// Slots are assigned by copy, so a std::vector inside T reuses its capacity
// once it has held the largest sample: after warm-up nothing allocates.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>

#include "fahr/common/sample_info.h"

namespace fahr::common {

template <class T>
class LatestSample {
 public:
  // Producer side. Several vendor threads may deliver; they serialise among
  // themselves on a mutex the consumer never touches.
  void publish(const T& value, const SampleInfo& info) {
    std::lock_guard lock(producer_mutex_);
    Slot& slot = slots_[producer_index_];
    slot.value = value;
    slot.info = info;
    const std::uint8_t previous = shared_.exchange(producer_index_ | kFresh, std::memory_order_acq_rel);
    producer_index_ = previous & kIndexMask;
    // seq_cst: Subscriber pairs this with its waiter count (a Dekker-style
    // handshake), so a waiter either sees the sample or is seen and woken.
    published_.fetch_add(1, std::memory_order_seq_cst);
  }

  // Consumer side: true if a sample newer than the one held has arrived; it
  // then becomes value()/info(). Wait-free.
  bool fetch() {
    if ((shared_.load(std::memory_order_acquire) & kFresh) == 0) return false;
    const std::uint8_t previous = shared_.exchange(consumer_index_, std::memory_order_acq_rel);
    consumer_index_ = previous & kIndexMask;
    has_value_ = true;
    return true;
  }

  bool has_value() const { return has_value_; }
  const T& value() const { return slots_[consumer_index_].value; }
  const SampleInfo& info() const { return slots_[consumer_index_].info; }
  // Samples published since construction (any thread may read it).
  std::uint64_t published() const { return published_.load(std::memory_order_seq_cst); }

 private:
  struct Slot {
    T value{};
    SampleInfo info{};
  };
  static constexpr std::uint8_t kFresh = 0x4;
  static constexpr std::uint8_t kIndexMask = 0x3;

  std::array<Slot, 3> slots_{};
  std::atomic<std::uint8_t> shared_{2};
  std::uint8_t producer_index_ = 0;
  std::uint8_t consumer_index_ = 1;
  bool has_value_ = false;
  std::mutex producer_mutex_;
  std::atomic<std::uint64_t> published_{0};
};

}  // namespace fahr::common
