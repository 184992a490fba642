// Borrowed CDR bytes decoded by Fast DDS's type support (see cdr_bytes.h).
#include "fahr/common/cdr_bytes.h"

#include <fastdds/dds/topic/TopicDataType.hpp>

namespace fahr::common {

bool decode_cdr(eprosima::fastdds::dds::TopicDataType& type, std::span<const std::uint8_t> bytes,
                void* sample) {
  eprosima::fastrtps::rtps::SerializedPayload_t payload;
  // The decoder only reads; the payload gives the pointer back before it
  // would free it.
  payload.data = const_cast<std::uint8_t*>(bytes.data());
  payload.length = static_cast<std::uint32_t>(bytes.size());
  payload.max_size = payload.length;
  const bool ok = type.deserialize(&payload, sample);
  payload.data = nullptr;
  return ok;
}

}  // namespace fahr::common
