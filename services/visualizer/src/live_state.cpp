// Newest bytes per topic and key.
#include "fahr/visualizer_service/live_state.h"

#include <algorithm>

#include "fahr/common/wire_header.h"

namespace fahr::visualizer_service {

const std::array<TopicInfo, kTopicCount>& topic_table() {
  static const std::array<TopicInfo, kTopicCount> table = {{
      {"fahr/DevicePose", "fahr::msg::DevicePose", true},
      {"fahr/ForceCommand", "fahr::msg::ForceCommand", true},
      {"fahr/ContactSet", "fahr::msg::ContactSet", true},
      {"fahr/DeformationState", "fahr::msg::DeformationState", true},
      {"fahr/SceneDescription", "fahr::msg::SceneDescription", true},
      {"fahr/ServiceStatus", "fahr::msg::ServiceStatus", true},
      {"fahr/GlotticView", "fahr::msg::GlotticView", true},
  }};
  return table;
}

std::size_t topic_index(std::string_view name) {
  const auto& t = topic_table();
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t[i].name == name) return i;
  }
  return kTopicCount;
}

LiveState::LiveState() {
  slots_.reserve(kMaxSlots);
}

void LiveState::put(std::size_t topic, std::span<const std::uint8_t> cdr, std::int64_t receive_ns) {
  received_.fetch_add(1, std::memory_order_relaxed);
  const auto wk = topic < kTopicCount ? common::read_wire_header(cdr, topic_table()[topic].keyed)
                                      : std::nullopt;
  if (!wk) {
    malformed_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  std::lock_guard lock(mutex_);
  auto it = std::find_if(slots_.begin(), slots_.end(),
                         [&](const Slot& s) { return s.topic == topic && s.key == wk->key; });
  if (it == slots_.end()) {
    if (slots_.size() >= kMaxSlots) {
      slots_full_.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    slots_.push_back(Slot{topic, wk->key, 0, 0, {}});
    it = slots_.end() - 1;
  }
  it->bytes.assign(cdr.begin(), cdr.end());
  it->receive_ns = receive_ns;
  it->version = next_version_++;
}

std::size_t LiveState::collect(std::vector<Slot>& out) const {
  std::lock_guard lock(mutex_);
  if (batches_.load() > 0) return 0;  // a seek's refill under way: its end is the change
  if (out.size() < slots_.size()) out.resize(slots_.size());
  std::size_t changed = 0;
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    const Slot& s = slots_[i];
    Slot& o = out[i];
    if (o.version == s.version && o.topic == s.topic && o.key == s.key) continue;
    o.topic = s.topic;
    o.key = s.key;
    o.version = s.version;
    o.receive_ns = s.receive_ns;
    o.bytes.assign(s.bytes.begin(), s.bytes.end());
    ++changed;
  }
  return changed;
}

void LiveState::clear_streams() {
  std::lock_guard lock(mutex_);
  for (auto& s : slots_) {
    if (s.topic == kSceneDescription) continue;
    s.bytes.clear();
    s.version = next_version_++;
  }
}

LiveState::Stats LiveState::stats() const {
  return {received_.load(), malformed_.load(), slots_full_.load()};
}

}  // namespace fahr::visualizer_service
