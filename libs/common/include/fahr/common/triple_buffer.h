// A triple buffer for one producer thread and one consumer thread that
// build and read large values in place: the producer fills back(), then
// publish() swaps it in; the consumer's fetch() takes the newest published
// value without waiting, locking or copying. Neither side ever waits for
// the other, so a slow producer (a FEM state digest) cannot stall a 1 kHz
// consumer, and a consumer never sees a value while it is being written.
//
// Unlike LatestSample (values delivered by vendor threads, copied in under a
// producer mutex), the slots here are built in place by exactly one thread:
// a digest of several hundred kilobytes is not copied twice per state.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <type_traits>

namespace fahr::common {

template <class T>
class TripleBuffer {
 public:
  TripleBuffer() = default;
  // Every slot starts as a copy of `initial` (capacity reserved up front, so
  // building in a slot later allocates nothing).
  explicit TripleBuffer(const T& initial) : slots_{initial, initial, initial} {}
  // Every slot from its own call of `make` (for values that own resources
  // no two slots may share).
  template <class Make>
  requires std::is_invocable_r_v<T, Make&>
  explicit TripleBuffer(Make make) : slots_{make(), make(), make()} {}

  TripleBuffer(const TripleBuffer&) = delete;
  TripleBuffer& operator=(const TripleBuffer&) = delete;

  // Producer side: the slot to build the next value in. Its content is an
  // older value (two publications back), not necessarily the newest one.
  T& back() { return slots_[producer_index_]; }
  // Makes back() the newest value and hands the producer another slot.
  void publish() {
    const std::uint8_t previous =
        shared_.exchange(producer_index_ | kFresh, std::memory_order_acq_rel);
    producer_index_ = previous & kIndexMask;
    // seq_cst: Subscriber pairs this count with its waiter count (a
    // Dekker-style handshake, via LatestSample), so a waiter either sees the
    // value or is seen and woken.
    published_.fetch_add(1, std::memory_order_seq_cst);
  }

  // Consumer side: true if a value newer than front() was published; it then
  // becomes front(). Wait-free.
  bool fetch() {
    if ((shared_.load(std::memory_order_acquire) & kFresh) == 0) return false;
    const std::uint8_t previous = shared_.exchange(consumer_index_, std::memory_order_acq_rel);
    consumer_index_ = previous & kIndexMask;
    has_value_ = true;
    return true;
  }
  bool has_value() const { return has_value_; }
  const T& front() const { return slots_[consumer_index_]; }
  // The consumer's slot is its own until the next fetch(): it may change it
  // (a publisher stamps the sample's header before writing it).
  T& front() { return slots_[consumer_index_]; }

  // Values published so far (any thread).
  std::uint64_t published() const { return published_.load(std::memory_order_seq_cst); }

 private:
  static constexpr std::uint8_t kFresh = 0x4;
  static constexpr std::uint8_t kIndexMask = 0x3;

  std::array<T, 3> slots_{};
  // The middle slot: its index, and kFresh when the consumer has not taken it.
  std::atomic<std::uint8_t> shared_{2};
  std::uint8_t producer_index_ = 0;
  std::uint8_t consumer_index_ = 1;
  bool has_value_ = false;
  std::atomic<std::uint64_t> published_{0};
};

}  // namespace fahr::common
