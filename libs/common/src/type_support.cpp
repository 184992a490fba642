// The type table behind detail::type_support<T>(): for each topic type the
// fastddsgen TopicDataType (Fast DDS, and CDR for Cyclone) and the idlc
// descriptor (Cyclone discovery).
#include "contact_setPubSubTypes.h"
#include "deformation_statePubSubTypes.h"
#include "device_posePubSubTypes.h"
#include "fahr/common/backend.h"
#include "fahr/common/topics.h"
#include "force_commandPubSubTypes.h"
#include "glottic_viewPubSubTypes.h"
#include "scene_descriptionPubSubTypes.h"
#include "service_statusPubSubTypes.h"
#include "sim_clockPubSubTypes.h"

// After Fast DDS headers (Cyclone macros clash with them).
#include <dds/dds.h>

// idlc's descriptors, declared here rather than through idlc's headers,
// whose file names collide with fastddsgen's.
extern "C" {
extern const dds_topic_descriptor_t fahr_msg_DevicePose_desc;
extern const dds_topic_descriptor_t fahr_msg_ForceCommand_desc;
extern const dds_topic_descriptor_t fahr_msg_ContactSet_desc;
extern const dds_topic_descriptor_t fahr_msg_DeformationState_desc;
extern const dds_topic_descriptor_t fahr_msg_SceneDescription_desc;
extern const dds_topic_descriptor_t fahr_msg_ServiceStatus_desc;
extern const dds_topic_descriptor_t fahr_msg_ServiceEvents_desc;
extern const dds_topic_descriptor_t fahr_msg_SimClock_desc;
extern const dds_topic_descriptor_t fahr_msg_StepAck_desc;
extern const dds_topic_descriptor_t fahr_msg_GlotticView_desc;
}

namespace fahr::common::detail {
namespace {

template <class T, class PubSub>
TypeSupport make_support(const char* name, const dds_topic_descriptor_t& descriptor) {
  return TypeSupport{
      name,
      []() -> void* { return new PubSub(); },
      &descriptor,
      []() -> void* { return new T(); },
      [](void* sample) { delete static_cast<T*>(sample); },
      [](void* destination, const void* source) {
        *static_cast<T*>(destination) = *static_cast<const T*>(source);
      },
  };
}

}  // namespace

#define FAHR_TYPE_SUPPORT(Type)                                                        \
  template <>                                                                          \
  const TypeSupport& type_support<msg::Type>() {                                       \
    static const TypeSupport support = make_support<msg::Type, msg::Type##PubSubType>( \
        "fahr::msg::" #Type, fahr_msg_##Type##_desc);                                  \
    return support;                                                                    \
  }

FAHR_TYPE_SUPPORT(DevicePose)
FAHR_TYPE_SUPPORT(ForceCommand)
FAHR_TYPE_SUPPORT(ContactSet)
FAHR_TYPE_SUPPORT(DeformationState)
FAHR_TYPE_SUPPORT(SceneDescription)
FAHR_TYPE_SUPPORT(ServiceStatus)
FAHR_TYPE_SUPPORT(ServiceEvents)
FAHR_TYPE_SUPPORT(SimClock)
FAHR_TYPE_SUPPORT(StepAck)
FAHR_TYPE_SUPPORT(GlotticView)

#undef FAHR_TYPE_SUPPORT

}  // namespace fahr::common::detail
