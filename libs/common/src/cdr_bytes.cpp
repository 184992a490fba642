// CDR bytes decoded and encoded by Fast DDS's type support (see cdr_bytes.h).
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

bool encode_cdr(eprosima::fastdds::dds::TopicDataType& type, const void* sample,
                std::vector<std::uint8_t>& out) {
  void* data = const_cast<void*>(sample);  // the serialiser only reads
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.getSerializedSizeProvider(data)());
  if (!type.serialize(data, &payload)) return false;
  out.assign(payload.data, payload.data + payload.length);
  return true;
}

}  // namespace fahr::common
