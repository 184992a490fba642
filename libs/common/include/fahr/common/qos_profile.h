// QoS named per topic role, one place for both vendors. A zero duration
// means "not set" (no deadline, automatic liveliness, infinite lifespan).
#pragma once

#include <chrono>
#include <string_view>

namespace fahr::common {

enum class Reliability { kBestEffort, kReliable };
enum class Durability { kVolatile, kTransientLocal };

// The roles of the topic table in docs/design/topics-and-qos.md.
enum class TopicRole {
  kServoStream,  // DevicePose, ForceCommand: 1 kHz, newest wins, never retransmit
  kStateStream,  // ContactSet, DeformationState: reliable, newest wins
  kLatched,      // SceneDescription: once, late joiners get it
  kReport,       // ServiceStatus, ServiceEvents: reliable, bounded history
  kLockstep,     // SimClock, StepAck: reliable, late joiners get the newest
};

struct QosProfile {
  Reliability reliability = Reliability::kReliable;
  Durability durability = Durability::kVolatile;
  // Samples kept per instance; 0 keeps all (within the vendor's limits).
  int history_depth = 1;
  // Longest allowed gap between samples of an instance.
  std::chrono::nanoseconds deadline{0};
  // Manual-by-topic liveliness lease: a writer that writes nothing for this
  // long (a hung loop, a SIGSTOPped process) is reported not alive.
  std::chrono::nanoseconds liveliness_lease{0};
  // A sample older than this is dropped instead of delivered.
  std::chrono::nanoseconds lifespan{0};

  // The defaults of a role; services override deadlines from their rates.
  static QosProfile for_role(TopicRole role);
};

}  // namespace fahr::common
