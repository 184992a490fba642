// Topic names and QoS shared by the multi-process tests and their peer.
#pragma once

#include <chrono>
#include <string>

#include "fahr/common/qos_profile.h"
#include "fahr/common/topics.h"

namespace fahr::test {

inline constexpr const char* kQosTopic = "fahr/test/qos";

template <class T>
std::string ping_topic() {
  return "fahr/test/ping/" + std::string(common::TopicTraits<T>::kName.substr(5));
}
template <class T>
std::string pong_topic() {
  return "fahr/test/pong/" + std::string(common::TopicTraits<T>::kName.substr(5));
}

// Reliable with room for every sample of a burst; transient local because
// each side learns of a match at its own moment, and a sample written
// before the writer saw the reader must still reach it.
inline common::QosProfile test_qos() {
  common::QosProfile qos = common::QosProfile::for_role(common::TopicRole::kReport);
  qos.durability = common::Durability::kTransientLocal;
  return qos;
}

inline common::QosProfile qos_under_test(int deadline_ms, int lease_ms) {
  common::QosProfile qos;
  qos.reliability = common::Reliability::kReliable;
  qos.history_depth = 1;
  qos.deadline = std::chrono::milliseconds(deadline_ms);
  qos.liveliness_lease = std::chrono::milliseconds(lease_ms);
  return qos;
}

}  // namespace fahr::test
