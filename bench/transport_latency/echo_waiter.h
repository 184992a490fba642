// The newest echoed id, handed from a vendor thread to the pinging thread.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>

namespace fahr::bench {

class EchoWaiter {
 public:
  void arrived(std::uint64_t id) {
    {
      std::lock_guard lock(mutex_);
      last_ = id;
    }
    cv_.notify_one();
  }
  bool wait(std::uint64_t id, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, timeout, [&] { return last_ == id; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::uint64_t last_ = ~0ULL;
};

}  // namespace fahr::bench
