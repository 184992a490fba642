// Every fahr topic: its message type (generated from idl/), its DDS topic
// name and its QoS role. The one table services and tools agree on.
#pragma once

#include <string_view>

#include "contact_set.h"
#include "deformation_state.h"
#include "device_pose.h"
#include "fahr/common/qos_profile.h"
#include "force_command.h"
#include "glottic_view.h"
#include "scene_description.h"
#include "service_status.h"
#include "sim_clock.h"

namespace fahr::common {

template <class T>
struct TopicTraits;

#define FAHR_TOPIC(Type, role)                               \
  template <>                                                \
  struct TopicTraits<msg::Type> {                            \
    static constexpr std::string_view kName = "fahr/" #Type; \
    static constexpr TopicRole kRole = TopicRole::role;      \
  }

// The macro only spells out the table; it keeps names and types in step.
FAHR_TOPIC(DevicePose, kServoStream);
FAHR_TOPIC(ForceCommand, kServoStream);
FAHR_TOPIC(ContactSet, kStateStream);
FAHR_TOPIC(DeformationState, kStateStream);
FAHR_TOPIC(SceneDescription, kLatched);
FAHR_TOPIC(ServiceStatus, kReport);
FAHR_TOPIC(ServiceEvents, kReport);
FAHR_TOPIC(SimClock, kLockstep);
FAHR_TOPIC(StepAck, kLockstep);
FAHR_TOPIC(GlotticView, kReport);

#undef FAHR_TOPIC

}  // namespace fahr::common
