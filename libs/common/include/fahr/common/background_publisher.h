// Writes the newest of a stream of samples from a thread of its own. The
// 1 kHz haptic tick builds its ContactSet in place (back()), hands it over
// (publish(): wait-free, no system call) and goes on; this thread pays for
// the DDS write, the sample's serialisation and send, which took the tick
// tens of microseconds of CPU (bench/intubation.sh prints the tick's
// parts). The thread looks for a new sample every `period`: waking it on
// each hand-over instead costs the tick a futex wake, a system call whose
// tail showed in the tick's publishing part on this machine. A sample
// superseded before the thread got to it is not written: the reader (the
// FEM, at its own rate) only ever takes the newest, now up to one period
// later. Only for samples nobody waits on within the tick: the
// ForceCommand, which the device's servo loop does wait on, stays on the
// tick's thread.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <thread>
#include <type_traits>

#include "fahr/common/participant.h"
#include "fahr/common/publisher.h"
#include "fahr/common/triple_buffer.h"

namespace fahr::common {

template <class T>
class BackgroundPublisher {
 public:
  // make(): a sample with the capacity the producer will need (building in
  // a slot then allocates nothing); called once per slot.
  // period: how often the thread looks for a new sample, > 0.
  template <class Make>
  requires std::is_invocable_r_v<T, Make&> BackgroundPublisher(Participant& participant,
                                                               std::chrono::nanoseconds period,
                                                               Make make)
      : publisher_(participant), buffer_(make), period_(period), thread_([this] { run(); }) {}
  ~BackgroundPublisher() {
    stop_.store(true, std::memory_order_release);
    thread_.join();
  }
  BackgroundPublisher(const BackgroundPublisher&) = delete;
  BackgroundPublisher& operator=(const BackgroundPublisher&) = delete;

  // Producer (one thread): the slot to build the next sample in. It holds an
  // older sample, to be overwritten whole.
  T& back() { return buffer_.back(); }
  // Producer: hands back() to the writing thread.
  void publish() { buffer_.publish(); }

  // Any thread: samples handed over and samples written (the difference were
  // superseded first, or refused by the vendor: see refused()).
  std::uint64_t handed() const { return buffer_.published(); }
  std::uint64_t written() const { return written_.load(std::memory_order_relaxed); }
  std::uint64_t refused() const { return refused_.load(std::memory_order_relaxed); }

 private:
  void run() {
    while (!stop_.load(std::memory_order_acquire)) {
      if (buffer_.fetch()) {
        if (publisher_.write(buffer_.front())) {
          written_.fetch_add(1, std::memory_order_relaxed);
        } else {
          refused_.fetch_add(1, std::memory_order_relaxed);
        }
      }
      std::this_thread::sleep_for(period_);
    }
  }

  Publisher<T> publisher_;
  TripleBuffer<T> buffer_;
  std::chrono::nanoseconds period_;
  std::atomic<bool> stop_{false};
  std::atomic<std::uint64_t> written_{0};
  std::atomic<std::uint64_t> refused_{0};
  std::thread thread_;  // last: starts once everything above exists
};

}  // namespace fahr::common
