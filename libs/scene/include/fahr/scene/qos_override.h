// Per-topic QoS overrides. Only the fields a scene sets replace the transport's
// profile of that topic (docs/design/topics-and-qos.md).
#pragma once

#include <array>
#include <chrono>
#include <optional>
#include <string_view>

namespace fahr::scene {

enum class Reliability { kReliable, kBestEffort };

std::string_view to_string(Reliability reliability);

// The topics a scene may override, as named in idl/.
inline constexpr std::array<std::string_view, 9> kTopicNames = {
    "DevicePose",    "ForceCommand",  "ContactSet", "DeformationState", "SceneDescription",
    "ServiceStatus", "ServiceEvents", "SimClock",   "StepAck"};

struct QosOverride {
  std::optional<std::chrono::nanoseconds> deadline;  // (0, 10 s]
  std::optional<int> history_depth;                  // keep last N, [1, 100000]
  std::optional<Reliability> reliability;
};

}  // namespace fahr::scene
