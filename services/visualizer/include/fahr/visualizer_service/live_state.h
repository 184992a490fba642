// The visualizer's one store between the sources (DDS callbacks or the
// replay thread) and the server: the newest CDR bytes of each topic and key.
// A source's put() copies the bytes into its slot under a mutex held for a
// memcpy (a slot's vector keeps its capacity, so after the first samples it
// allocates nothing) and never waits for a client: however slow the
// clients, the services' writers see one more quick reader.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <span>
#include <string_view>
#include <vector>

namespace fahr::visualizer_service {

// The topics the visualizer shows and serves, in a fixed order.
enum TopicIndex : std::size_t {
  kDevicePose,
  kForceCommand,
  kContactSet,
  kDeformationState,
  kSceneDescription,
  kServiceStatus,
  kGlotticView,
  kTopicCount
};

struct TopicInfo {
  std::string_view name;       // "fahr/DevicePose"
  std::string_view type_name;  // "fahr::msg::DevicePose"
  bool keyed = true;           // a key (device, body, service id) follows the header
};
const std::array<TopicInfo, kTopicCount>& topic_table();
// kTopicCount if `name` is not one of them.
std::size_t topic_index(std::string_view name);

// One topic and key's newest sample.
struct Slot {
  std::size_t topic = kTopicCount;
  std::uint32_t key = 0;
  std::uint64_t version = 0;  // 0: empty; grows with every put
  std::int64_t receive_ns = 0;
  std::vector<std::uint8_t> bytes;
};

class LiveState {
 public:
  // Slots in all: topics x keys seen. A sample of a new key past this many
  // is dropped and counted (a misbehaving writer cannot grow the store).
  static constexpr std::size_t kMaxSlots = 96;

  LiveState();

  // A source's sample: `cdr` with its encapsulation header. Malformed bytes
  // (too short, not XCDR1) are counted and dropped.
  void put(std::size_t topic, std::span<const std::uint8_t> cdr, std::int64_t receive_ns);

  // Copies every slot whose version differs from out[i].version into out[i]
  // (out grows to the slots in use); returns how many changed.
  std::size_t collect(std::vector<Slot>& out) const;

  // Forgets every sample but the scene's (a replay seek).
  void clear_streams();

  // A replay seek's clear and refill as one change: while a Batch lives,
  // collect() reports nothing, so the server never sends the emptied store
  // (a page would read "no ForceCommand yet" there) and its next tick sends
  // the refilled one.
  class Batch {
   public:
    explicit Batch(LiveState& live) : live_(live) { live_.batches_.fetch_add(1); }
    ~Batch() { live_.batches_.fetch_sub(1); }
    Batch(const Batch&) = delete;
    Batch& operator=(const Batch&) = delete;

   private:
    LiveState& live_;
  };

  struct Stats {
    std::uint64_t received = 0, malformed = 0, slots_full = 0;
  };
  Stats stats() const;

 private:
  mutable std::mutex mutex_;
  std::vector<Slot> slots_;
  std::uint64_t next_version_ = 1;
  std::atomic<std::uint64_t> received_{0}, malformed_{0}, slots_full_{0};
  std::atomic<int> batches_{0};
};

}  // namespace fahr::visualizer_service
