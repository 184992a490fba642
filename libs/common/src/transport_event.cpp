// The bounded event history.
#include "fahr/common/transport_event.h"

#include <cstring>

namespace fahr::common {

std::string_view TransportEvent::topic_name() const {
  return {topic.data(), strnlen(topic.data(), topic.size())};
}

void EventLog::record(const TransportEvent& event) {
  counts_[static_cast<std::size_t>(event.kind)].fetch_add(event.total_count_change);
  if (event.kind == EventKind::kLivelinessChanged) {
    alive_writers_.store(event.current_count);
    not_alive_writers_.store(event.not_alive_count);
  }
  std::function<void(const TransportEvent&)> observer;
  {
    std::lock_guard lock(mutex_);
    ring_[(head_ + size_) % kCapacity] = event;
    if (size_ < kCapacity) {
      ++size_;
    } else {
      head_ = (head_ + 1) % kCapacity;
      ++dropped_;
    }
    observer = observer_;
  }
  if (observer) observer(event);
}

std::int64_t EventLog::count(EventKind kind) const {
  return counts_[static_cast<std::size_t>(kind)].load();
}

std::uint64_t EventLog::drain(const std::function<void(const TransportEvent&)>& sink) {
  std::lock_guard lock(mutex_);
  for (std::size_t i = 0; i < size_; ++i) sink(ring_[(head_ + i) % kCapacity]);
  head_ = 0;
  size_ = 0;
  const std::uint64_t dropped = dropped_;
  dropped_ = 0;
  return dropped;
}

void EventLog::set_observer(std::function<void(const TransportEvent&)> observer) {
  std::lock_guard lock(mutex_);
  observer_ = std::move(observer);
}

}  // namespace fahr::common
