// CDR bytes as they travel (the 4-byte encapsulation header first) decoded
// into a sample by Fast DDS's generated type support, the bytes borrowed,
// not copied. What the Cyclone back-end, the recorder and the tools that
// read recordings share.
#pragma once

#include <cstdint>
#include <span>

namespace eprosima::fastdds::dds {
class TopicDataType;
}  // namespace eprosima::fastdds::dds

namespace fahr::common {

// Decodes `bytes` into *sample (of the type `type` describes). False if the
// bytes do not decode. Allocates only what the sample's own members need.
bool decode_cdr(eprosima::fastdds::dds::TopicDataType& type, std::span<const std::uint8_t> bytes,
                void* sample);

// The same with the generated PubSub type named (e.g. msg::DevicePosePubSubType).
template <class PubSub, class Sample>
bool decode_cdr(std::span<const std::uint8_t> bytes, Sample& sample) {
  PubSub type;
  return decode_cdr(type, bytes, &sample);
}

}  // namespace fahr::common
