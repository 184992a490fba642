// A triple buffer holding the newest sample of a topic: producers (vendor
// threads) never wait for the consumer, and the consumer (a 1 kHz loop)
// takes the newest sample without locking or allocating.
//
// Slots are assigned by copy, so a std::vector inside T reuses its capacity
// once it has held the largest sample: after warm-up nothing allocates.
#pragma once

#include <cstdint>
#include <mutex>

#include "fahr/common/sample_info.h"
#include "fahr/common/triple_buffer.h"

namespace fahr::common {

template <class T>
class LatestSample {
 public:
  // Producer side. Several vendor threads may deliver; they serialise among
  // themselves on a mutex the consumer never touches.
  void publish(const T& value, const SampleInfo& info) {
    std::lock_guard lock(producer_mutex_);
    Slot& slot = buffer_.back();
    slot.value = value;
    slot.info = info;
    buffer_.publish();
  }

  // Consumer side: true if a sample newer than the one held has arrived; it
  // then becomes value()/info(). Wait-free.
  bool fetch() { return buffer_.fetch(); }

  bool has_value() const { return buffer_.has_value(); }
  const T& value() const { return buffer_.front().value; }
  const SampleInfo& info() const { return buffer_.front().info; }
  // Samples published since construction (any thread may read it).
  std::uint64_t published() const { return buffer_.published(); }

 private:
  struct Slot {
    T value{};
    SampleInfo info{};
  };
  TripleBuffer<Slot> buffer_;
  std::mutex producer_mutex_;
};

}  // namespace fahr::common
