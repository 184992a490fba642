// The default raw reader: typed samples serialized again with the
// fastddsgen type, for backends that carry no bytes (the in-process bus).
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <memory>

#include "fahr/common/backend.h"

namespace fahr::common::detail {
namespace {

using eprosima::fastdds::dds::TopicDataType;
using eprosima::fastrtps::rtps::SerializedPayload_t;

class ReserialisingReader final : public ReaderBackend, private SampleSink {
 public:
  ReserialisingReader(ParticipantBackend& backend, const EndpointSpec& spec, RawSampleSink* sink)
      : fast_type_(static_cast<TopicDataType*>(spec.type->make_fast_type())), sink_(sink) {
    reader_ = backend.create_reader(spec, this);
  }
  ~ReserialisingReader() override { reader_.reset(); }  // stop deliveries first
  int matched_writers() const override { return reader_->matched_writers(); }

 private:
  void deliver(const void* sample, std::int64_t source_time_ns, std::uint64_t) override {
    void* data = const_cast<void*>(sample);
    const std::uint32_t size = fast_type_->getSerializedSizeProvider(data)();
    if (payload_.max_size < size) payload_.reserve(size);
    if (!fast_type_->serialize(data, &payload_)) return;
    sink_->deliver_raw(payload_.data, payload_.length, source_time_ns);
  }

  std::unique_ptr<TopicDataType> fast_type_;
  RawSampleSink* sink_;
  SerializedPayload_t payload_;
  std::unique_ptr<ReaderBackend> reader_;
};

}  // namespace

std::unique_ptr<ReaderBackend> ParticipantBackend::create_raw_reader(const EndpointSpec& spec,
                                                                     RawSampleSink* sink) {
  return std::make_unique<ReserialisingReader>(*this, spec, sink);
}

}  // namespace fahr::common::detail
