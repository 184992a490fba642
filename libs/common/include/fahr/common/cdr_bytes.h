// CDR bytes as they travel (the 4-byte encapsulation header first) decoded
// into a sample by Fast DDS's generated type support, the bytes borrowed,
// not copied. What the Cyclone back-end, the recorder and the tools that
// read recordings share.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

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

// The reverse: *sample (of the type `type` describes) as CDR bytes with
// their encapsulation header, into `out` (resized). False if it does not
// serialise.
bool encode_cdr(eprosima::fastdds::dds::TopicDataType& type, const void* sample,
                std::vector<std::uint8_t>& out);

template <class PubSub, class Sample>
bool encode_cdr(const Sample& sample, std::vector<std::uint8_t>& out) {
  PubSub type;
  return encode_cdr(type, &sample, out);
}

}  // namespace fahr::common
