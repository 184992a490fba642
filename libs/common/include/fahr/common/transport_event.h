// QoS and discovery events of every vendor, surfaced uniformly. Vendors
// report them on their own threads; EventLog keeps a bounded history for the
// ServiceEvents topic and cumulative counters for tests and status.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string_view>

namespace fahr::common {

// Same order as fahr::msg::QosEventKind in idl/fahr/service_status.idl.
enum class EventKind {
  kRequestedDeadlineMissed,
  kOfferedDeadlineMissed,
  kSampleLost,
  kSampleRejected,
  kSubscriptionMatched,
  kPublicationMatched,
  kRequestedIncompatibleQos,
  kOfferedIncompatibleQos,
  kLivelinessChanged,
  kLivelinessLost,
};
inline constexpr int kEventKindCount = 10;

struct TransportEvent {
  std::int64_t time_ns = 0;  // wall clock when fahr saw it
  EventKind kind = EventKind::kSampleLost;
  std::array<char, 64> topic{};  // NUL-terminated, truncated
  std::int32_t total_count = 0;
  std::int32_t total_count_change = 0;
  std::int32_t current_count = 0;    // matched: current matches; liveliness: alive writers
  std::int32_t not_alive_count = 0;  // liveliness: writers not alive

  std::string_view topic_name() const;
};

class EventLog {
 public:
  static constexpr std::size_t kCapacity = 512;

  // Called from vendor threads. Never blocks for long; drops the oldest
  // event when full and counts the drop.
  void record(const TransportEvent& event);

  // Cumulative number of events of a kind (total_count_change summed).
  std::int64_t count(EventKind kind) const;
  // Latest liveliness state reported for readers of a topic, summed.
  std::int32_t alive_writers() const { return alive_writers_.load(); }
  std::int32_t not_alive_writers() const { return not_alive_writers_.load(); }

  // Moves the buffered events out, oldest first; returns how many were lost
  // to overflow since the previous drain.
  std::uint64_t drain(const std::function<void(const TransportEvent&)>& sink);

  // Optional observer, called on the vendor thread for each event.
  void set_observer(std::function<void(const TransportEvent&)> observer);

 private:
  mutable std::mutex mutex_;
  std::array<TransportEvent, kCapacity> ring_{};
  std::size_t head_ = 0;
  std::size_t size_ = 0;
  std::uint64_t dropped_ = 0;
  std::function<void(const TransportEvent&)> observer_;
  std::array<std::atomic<std::int64_t>, kEventKindCount> counts_{};
  std::atomic<std::int32_t> alive_writers_{0};
  std::atomic<std::int32_t> not_alive_writers_{0};
};

}  // namespace fahr::common
