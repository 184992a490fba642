// Role defaults. Deadlines are left to services (they know their rates);
// the values here are what a role needs whatever the rate.
#include "fahr/common/qos_profile.h"

namespace fahr::common {

using std::chrono::milliseconds;

QosProfile QosProfile::for_role(TopicRole role) {
  QosProfile qos;
  switch (role) {
    case TopicRole::kServoStream:
      // A retransmitted pose or force is older than the next one: never
      // retransmit, never queue.
      qos.reliability = Reliability::kBestEffort;
      qos.history_depth = 1;
      qos.liveliness_lease = milliseconds(100);
      break;
    case TopicRole::kStateStream:
      qos.reliability = Reliability::kReliable;
      qos.history_depth = 1;
      qos.liveliness_lease = milliseconds(500);
      break;
    case TopicRole::kLatched:
      qos.reliability = Reliability::kReliable;
      qos.durability = Durability::kTransientLocal;
      qos.history_depth = 1;
      break;
    case TopicRole::kReport:
      // Reports must all reach the logger; 100 per service bounds memory.
      qos.reliability = Reliability::kReliable;
      qos.history_depth = 100;
      break;
    case TopicRole::kLockstep:
      // Late joiners need the newest grant; a few steps of history cover a
      // consumer that reads while the producer publishes the next one.
      qos.reliability = Reliability::kReliable;
      qos.durability = Durability::kTransientLocal;
      qos.history_depth = 8;
      break;
  }
  return qos;
}

}  // namespace fahr::common
