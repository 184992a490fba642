// Ping and echo through Fast DDS's own API, with the same QoS the
// transport uses, for the transport/raw ratio.
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <functional>
#include <stdexcept>

#include "deformation_statePubSubTypes.h"
#include "device_posePubSubTypes.h"
#include "echo_waiter.h"
#include "ping_path.h"

namespace fahr::bench {
namespace {

namespace dds = eprosima::fastdds::dds;

std::uint64_t id_of(const msg::DevicePose& s) {
  return s.servo_tick();
}
std::uint64_t id_of(const msg::DeformationState& s) {
  return s.step();
}
void set_id(msg::DevicePose& s, std::uint64_t id) {
  s.servo_tick(id);
}
void set_id(msg::DeformationState& s, std::uint64_t id) {
  s.step(id);
}

// A participant with one writer and one reader whose listener hands every
// sample to `on_sample`.
template <class T, class PubSub>
class RawFastEndpoint : private dds::DataReaderListener {
 public:
  RawFastEndpoint(std::uint32_t domain, const char* out_topic, const char* in_topic,
                  std::function<void(T&)> on_sample)
      : on_sample_(std::move(on_sample)) {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    participant_ = factory->create_participant(domain, factory->get_default_participant_qos());
    if (participant_ == nullptr) throw std::runtime_error("raw Fast DDS: no participant");
    dds::TypeSupport type(new PubSub());
    type.register_type(participant_);
    auto* out = participant_->create_topic(out_topic, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    auto* in = participant_->create_topic(in_topic, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    dds::DataWriterQos wq = publisher_->get_default_datawriter_qos();
    dds::DataReaderQos rq = subscriber_->get_default_datareader_qos();
    wq.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    rq.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    wq.durability().kind = dds::VOLATILE_DURABILITY_QOS;
    rq.durability().kind = dds::VOLATILE_DURABILITY_QOS;
    wq.history().kind = dds::KEEP_LAST_HISTORY_QOS;
    rq.history().kind = dds::KEEP_LAST_HISTORY_QOS;
    wq.history().depth = 1;
    rq.history().depth = 1;
    if (type->m_typeSize > 64 * 1024) {  // as the transport does for large types
      wq.endpoint().history_memory_policy = eprosima::fastrtps::rtps::DYNAMIC_REUSABLE_MEMORY_MODE;
      rq.endpoint().history_memory_policy = eprosima::fastrtps::rtps::DYNAMIC_REUSABLE_MEMORY_MODE;
    }
    writer_ = publisher_->create_datawriter(out, wq);
    reader_ = subscriber_->create_datareader(in, rq, this);
  }
  ~RawFastEndpoint() override {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  void write(T& sample) { writer_->write(&sample); }

 private:
  void on_data_available(dds::DataReader* reader) override {
    dds::SampleInfo info;
    while (reader->take_next_sample(&scratch_, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) on_sample_(scratch_);
    }
  }

  std::function<void(T&)> on_sample_;
  T scratch_;
  dds::DomainParticipant* participant_ = nullptr;
  dds::Publisher* publisher_ = nullptr;
  dds::Subscriber* subscriber_ = nullptr;
  dds::DataWriter* writer_ = nullptr;
  dds::DataReader* reader_ = nullptr;
};

template <class T, class PubSub>
class RawFastPing final : public PingPath {
 public:
  RawFastPing(std::uint32_t domain, const Payload& payload)
      : endpoint_(domain, kRawPing, kRawPong, [this](T& s) { waiter_.arrived(id_of(s)); }) {
    if constexpr (std::is_same_v<T, msg::DeformationState>) {
      sample_.positions_m().assign(payload.payload_bytes / 8, 0.5F);
      sample_.velocities_mps().assign(payload.payload_bytes / 8, -0.5F);
    }
  }
  void ping(std::uint64_t id) override {
    set_id(sample_, id);
    endpoint_.write(sample_);
  }
  bool wait_echo(std::uint64_t id, std::chrono::milliseconds timeout) override {
    return waiter_.wait(id, timeout);
  }

 private:
  EchoWaiter waiter_;
  T sample_;
  RawFastEndpoint<T, PubSub> endpoint_;
};

template <class T, class PubSub>
class RawFastEcho final : public EchoPath {
 public:
  explicit RawFastEcho(std::uint32_t domain)
      : endpoint_(domain, kRawPong, kRawPing, [this](T& s) { endpoint_.write(s); }) {}

 private:
  RawFastEndpoint<T, PubSub> endpoint_;
};

}  // namespace

std::unique_ptr<PingPath> make_raw_fast_ping(std::uint32_t domain, const Payload& payload) {
  if (payload.small)
    return std::make_unique<RawFastPing<msg::DevicePose, msg::DevicePosePubSubType>>(domain,
                                                                                     payload);
  return std::make_unique<RawFastPing<msg::DeformationState, msg::DeformationStatePubSubType>>(
      domain, payload);
}

std::unique_ptr<EchoPath> make_raw_fast_echo(std::uint32_t domain, const Payload& payload) {
  if (payload.small)
    return std::make_unique<RawFastEcho<msg::DevicePose, msg::DevicePosePubSubType>>(domain);
  return std::make_unique<RawFastEcho<msg::DeformationState, msg::DeformationStatePubSubType>>(
      domain);
}

}  // namespace fahr::bench
