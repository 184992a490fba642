// Tick spans handed from a real-time loop to a reporter thread through a
// fixed-capacity single-producer/single-consumer ring: push() is wait-free
// and allocates nothing; when the reporter falls behind, new spans are
// dropped and counted rather than blocking the loop.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>

namespace fahr::common {

struct TickRecord {
  std::uint64_t tick = 0;
  std::int64_t start_ns = 0;     // monotonic clock at tick start
  std::int64_t duration_ns = 0;  // wall duration of the tick's work
  std::int64_t cpu_ns = 0;       // thread CPU time of the tick's work
};

class TickRecorder {
 public:
  static constexpr std::size_t kCapacity = 4096;  // 4 s of 1 kHz ticks

  // Loop thread only.
  void push(const TickRecord& record) {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    const std::size_t tail = tail_.load(std::memory_order_acquire);
    if (head - tail >= kCapacity) {
      dropped_.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    ring_[head % kCapacity] = record;
    head_.store(head + 1, std::memory_order_release);
  }

  // Reporter thread only: calls sink for every record, oldest first.
  template <class Sink>
  std::size_t drain(Sink&& sink) {
    const std::size_t head = head_.load(std::memory_order_acquire);
    std::size_t tail = tail_.load(std::memory_order_relaxed);
    const std::size_t n = head - tail;
    for (; tail != head; ++tail) sink(ring_[tail % kCapacity]);
    tail_.store(tail, std::memory_order_release);
    return n;
  }

  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

 private:
  std::array<TickRecord, kCapacity> ring_{};
  alignas(64) std::atomic<std::size_t> head_{0};
  alignas(64) std::atomic<std::size_t> tail_{0};
  std::atomic<std::uint64_t> dropped_{0};
};

}  // namespace fahr::common
