// Fast DDS 2.9 backend: the fastddsgen TopicDataTypes go straight to the
// vendor; listeners turn its statuses into TransportEvents.
#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fstream>
#include <map>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "backends.h"
#include "fahr/common/clock.h"
#include "fahr/common/config_error.h"

namespace fahr::common::detail {
namespace {

namespace dds = eprosima::fastdds::dds;
using eprosima::fastrtps::Duration_t;
using eprosima::fastrtps::rtps::SerializedPayload_t;

// Samples larger than this get a dynamically sized history instead of one
// preallocated at the type's bound (a DeformationState's bound is 1.7 MB).
constexpr std::uint32_t kPreallocateLimitBytes = 64 * 1024;

// Requested socket buffer size when a profile sets none; the kernel caps
// it at net.core.rmem_max / wmem_max (deployment/README.md).
constexpr std::uint32_t kSocketBufferBytes = 4U * 1024U * 1024U;

// The writer's GUID (prefix and entity id) folded into 64 bits (FNV-1a).
std::uint64_t writer_key(const dds::SampleInfo& info) {
  const auto& guid = info.sample_identity.writer_guid();
  std::uint64_t h = 14695981039346656037ULL;
  const auto mix = [&h](const auto& bytes) {
    for (const auto b : bytes) {
      h ^= static_cast<std::uint8_t>(b);
      h *= 1099511628211ULL;
    }
  };
  mix(guid.guidPrefix.value);
  mix(guid.entityId.value);
  return h;
}

Duration_t to_duration(std::chrono::nanoseconds d) {
  const auto ns = d.count();
  return Duration_t(static_cast<std::int32_t>(ns / 1'000'000'000),
                    static_cast<std::uint32_t>(ns % 1'000'000'000));
}

template <class Qos>
void apply_profile(const QosProfile& profile, std::uint32_t max_sample_bytes, Qos& qos) {
  qos.reliability().kind = profile.reliability == Reliability::kReliable
                               ? dds::RELIABLE_RELIABILITY_QOS
                               : dds::BEST_EFFORT_RELIABILITY_QOS;
  qos.durability().kind = profile.durability == Durability::kTransientLocal
                              ? dds::TRANSIENT_LOCAL_DURABILITY_QOS
                              : dds::VOLATILE_DURABILITY_QOS;
  if (profile.history_depth == 0) {
    qos.history().kind = dds::KEEP_ALL_HISTORY_QOS;
  } else {
    qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
    qos.history().depth = profile.history_depth;
  }
  if (profile.deadline.count() > 0) qos.deadline().period = to_duration(profile.deadline);
  if (profile.liveliness_lease.count() > 0) {
    qos.liveliness().kind = dds::MANUAL_BY_TOPIC_LIVELINESS_QOS;
    qos.liveliness().lease_duration = to_duration(profile.liveliness_lease);
    qos.liveliness().announcement_period = to_duration(profile.liveliness_lease / 3);
  }
  if (profile.lifespan.count() > 0) qos.lifespan().duration = to_duration(profile.lifespan);
  // Data sharing only ever applies to unkeyed types (SimClock is the only
  // one): off, so every topic takes the same path, and because
  // with it transient-local samples to a fresh reader went missing in about
  // one run in three (test_interop, SimClock, Fast DDS both ends).
  qos.data_sharing().off();
  if (max_sample_bytes > kPreallocateLimitBytes) {
    qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::DYNAMIC_REUSABLE_MEMORY_MODE;
  }
}

TransportEvent make_event(EventKind kind, std::string_view topic, std::int32_t total,
                          std::int32_t change) {
  TransportEvent event;
  event.time_ns = wall_now_ns();
  event.kind = kind;
  set_event_topic(event, topic);
  event.total_count = total;
  event.total_count_change = change;
  return event;
}

// Fast DDS keeps some status counts as uint32_t where the DDS specification has long; the
// count of one kind of event in a run stays far below 2^31.
TransportEvent make_event(EventKind kind, std::string_view topic, std::uint32_t total,
                          std::uint32_t change) {
  return make_event(kind, topic, static_cast<std::int32_t>(total),
                    static_cast<std::int32_t>(change));
}

// A sample as its serialized bytes (raw readers).
struct RawSample {
  std::vector<std::uint8_t> bytes;
};

// The TopicDataType of raw readers: the same type name, size bound and key
// as the generated type, but "deserializing" keeps the payload's bytes as
// they arrived (encapsulation header included).
class RawTopicType final : public dds::TopicDataType {
 public:
  explicit RawTopicType(const TypeSupport& type)
      : inner_(static_cast<dds::TopicDataType*>(type.make_fast_type())) {
    setName(type.type_name);
    m_typeSize = inner_->m_typeSize;
    m_isGetKeyDefined = inner_->m_isGetKeyDefined;
  }
  bool serialize(void* data, SerializedPayload_t* payload) override {
    const auto& raw = static_cast<RawSample*>(data)->bytes;
    if (payload->max_size < raw.size()) return false;
    std::copy(raw.begin(), raw.end(), payload->data);
    payload->length = static_cast<std::uint32_t>(raw.size());
    payload->encapsulation = raw.size() > 1 && raw[1] == 0 ? CDR_BE : CDR_LE;
    return true;
  }
  bool deserialize(SerializedPayload_t* payload, void* data) override {
    static_cast<RawSample*>(data)->bytes.assign(payload->data, payload->data + payload->length);
    return true;
  }
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
    return
        [data] { return static_cast<std::uint32_t>(static_cast<RawSample*>(data)->bytes.size()); };
  }
  void* createData() override { return new RawSample(); }
  void deleteData(void* data) override { delete static_cast<RawSample*>(data); }
  // Every keyed fahr type has one `@key unsigned long` right after its
  // 36-byte SampleHeader; its instance handle is that key big-endian,
  // zero-padded to 16 bytes, exactly what the generated getKey produces.
  bool getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* handle,
              bool /*force_md5*/) override {
    if (!m_isGetKeyDefined) return false;
    const auto& raw = static_cast<RawSample*>(data)->bytes;
    constexpr std::size_t kKeyAt = 4 + 36;
    if (raw.size() < kKeyAt + 4) return false;
    const bool little = raw[1] != 0;
    for (int i = 0; i < 16; ++i) handle->value[i] = 0;
    for (int i = 0; i < 4; ++i) {
      handle->value[i] = little ? raw[kKeyAt + 3 - i] : raw[kKeyAt + i];
    }
    return true;
  }

 private:
  std::unique_ptr<dds::TopicDataType> inner_;
};

class FastWriter final : public WriterBackend, private dds::DataWriterListener {
 public:
  FastWriter(dds::Publisher& publisher, dds::Topic& topic, const QosProfile& profile,
             std::uint32_t max_bytes, EventLog& events)
      : publisher_(publisher), topic_name_(topic.get_name()), events_(events) {
    dds::DataWriterQos qos = publisher.get_default_datawriter_qos();
    apply_profile(profile, max_bytes, qos);
    writer_ = publisher.create_datawriter(&topic, qos, this, dds::StatusMask::all());
    if (writer_ == nullptr) throw std::runtime_error("Fast DDS refused a writer on " + topic_name_);
  }
  ~FastWriter() override {
    writer_->set_listener(nullptr);
    publisher_.delete_datawriter(writer_);
  }

  bool write(const void* sample, std::int64_t source_time_ns) override {
    const eprosima::fastrtps::Time_t stamp(
        static_cast<std::int32_t>(source_time_ns / 1'000'000'000),
        static_cast<std::uint32_t>(source_time_ns % 1'000'000'000));
    return writer_->write_w_timestamp(const_cast<void*>(sample), dds::HANDLE_NIL, stamp) ==
           ReturnCode_t::RETCODE_OK;
  }
  void assert_liveliness() override { writer_->assert_liveliness(); }
  int matched_readers() const override { return matched_.load(); }
  bool wait_for_acks(std::chrono::nanoseconds timeout) override {
    return writer_->wait_for_acknowledgments(to_duration(timeout)) == ReturnCode_t::RETCODE_OK;
  }

 private:
  void on_publication_matched(dds::DataWriter*, const dds::PublicationMatchedStatus& s) override {
    matched_.store(s.current_count);
    auto event = make_event(EventKind::kPublicationMatched, topic_name_, s.total_count,
                            s.current_count_change);
    event.current_count = s.current_count;
    events_.record(event);
  }
  void on_offered_deadline_missed(dds::DataWriter*,
                                  const dds::OfferedDeadlineMissedStatus& s) override {
    events_.record(make_event(EventKind::kOfferedDeadlineMissed, topic_name_, s.total_count,
                              s.total_count_change));
  }
  void on_offered_incompatible_qos(dds::DataWriter*,
                                   const dds::OfferedIncompatibleQosStatus& s) override {
    events_.record(make_event(EventKind::kOfferedIncompatibleQos, topic_name_, s.total_count,
                              s.total_count_change));
  }
  void on_liveliness_lost(dds::DataWriter*, const dds::LivelinessLostStatus& s) override {
    events_.record(
        make_event(EventKind::kLivelinessLost, topic_name_, s.total_count, s.total_count_change));
  }

  dds::Publisher& publisher_;
  std::string topic_name_;
  EventLog& events_;
  dds::DataWriter* writer_ = nullptr;
  std::atomic<int> matched_{0};
};

class FastReader final : public ReaderBackend, private dds::DataReaderListener {
 public:
  // With `raw_sink` set (and `topic` of a RawTopicType) the reader hands
  // over bytes instead of typed samples.
  FastReader(dds::Subscriber& subscriber, dds::Topic& topic, const TypeSupport& type,
             const QosProfile& profile, std::uint32_t max_bytes, SampleSink* sink, EventLog& events,
             RawSampleSink* raw_sink = nullptr)
      : subscriber_(subscriber),
        topic_name_(topic.get_name()),
        type_(type),
        sink_(sink),
        raw_sink_(raw_sink),
        events_(events),
        scratch_(raw_sink != nullptr ? new RawSample() : type.new_sample()) {
    dds::DataReaderQos qos = subscriber.get_default_datareader_qos();
    apply_profile(profile, max_bytes, qos);
    reader_ = subscriber.create_datareader(&topic, qos, this, dds::StatusMask::all());
    if (reader_ == nullptr) throw std::runtime_error("Fast DDS refused a reader on " + topic_name_);
  }
  ~FastReader() override {
    reader_->set_listener(nullptr);
    subscriber_.delete_datareader(reader_);
    if (raw_sink_ != nullptr) {
      delete static_cast<RawSample*>(scratch_);
    } else {
      type_.delete_sample(scratch_);
    }
  }
  int matched_writers() const override { return matched_.load(); }

 private:
  void on_data_available(dds::DataReader* reader) override {
    dds::SampleInfo info;
    while (reader->take_next_sample(scratch_, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      if (raw_sink_ != nullptr) {
        const auto& raw = static_cast<RawSample*>(scratch_)->bytes;
        raw_sink_->deliver_raw(raw.data(), raw.size(), info.source_timestamp.to_ns());
      } else {
        sink_->deliver(scratch_, info.source_timestamp.to_ns(), writer_key(info));
      }
    }
  }
  void on_subscription_matched(dds::DataReader*, const dds::SubscriptionMatchedStatus& s) override {
    matched_.store(s.current_count);
    auto event = make_event(EventKind::kSubscriptionMatched, topic_name_, s.total_count,
                            s.current_count_change);
    event.current_count = s.current_count;
    events_.record(event);
  }
  void on_requested_deadline_missed(dds::DataReader*,
                                    const dds::RequestedDeadlineMissedStatus& s) override {
    events_.record(make_event(EventKind::kRequestedDeadlineMissed, topic_name_, s.total_count,
                              s.total_count_change));
  }
  void on_liveliness_changed(dds::DataReader*, const dds::LivelinessChangedStatus& s) override {
    auto event = make_event(EventKind::kLivelinessChanged, topic_name_,
                            s.alive_count + s.not_alive_count, 1);
    event.current_count = s.alive_count;
    event.not_alive_count = s.not_alive_count;
    events_.record(event);
  }
  void on_sample_rejected(dds::DataReader*, const dds::SampleRejectedStatus& s) override {
    events_.record(
        make_event(EventKind::kSampleRejected, topic_name_, s.total_count, s.total_count_change));
  }
  void on_requested_incompatible_qos(dds::DataReader*,
                                     const dds::RequestedIncompatibleQosStatus& s) override {
    events_.record(make_event(EventKind::kRequestedIncompatibleQos, topic_name_, s.total_count,
                              s.total_count_change));
  }
  void on_sample_lost(dds::DataReader*, const dds::SampleLostStatus& s) override {
    events_.record(
        make_event(EventKind::kSampleLost, topic_name_, s.total_count, s.total_count_change));
  }

  dds::Subscriber& subscriber_;
  std::string topic_name_;
  const TypeSupport& type_;
  SampleSink* sink_;
  RawSampleSink* raw_sink_;
  EventLog& events_;
  void* scratch_;
  dds::DataReader* reader_ = nullptr;
  std::atomic<int> matched_{0};
};

// The factory's default participant QoS from the vendor's own default file
// (or built in), read once, before any profile of fahr's is loaded.
const dds::DomainParticipantQos& vendor_default_participant_qos(
    dds::DomainParticipantFactory& factory) {
  static const dds::DomainParticipantQos qos = [&factory] {
    factory.load_profiles();
    factory.set_default_participant_qos(dds::PARTICIPANT_QOS_DEFAULT);
    return factory.get_default_participant_qos();
  }();
  return qos;
}

// profile_name of the <participant is_default_profile="true"> in a Fast DDS
// XML file, or empty.
std::string default_participant_profile(const std::string& file) {
  std::ifstream in(file);
  std::ostringstream whole;
  whole << in.rdbuf();
  const std::string text = whole.str();
  for (std::size_t at = text.find("<participant"); at != std::string::npos;
       at = text.find("<participant", at + 1)) {
    const std::size_t end = text.find('>', at);
    if (end == std::string::npos) break;
    const std::string tag = text.substr(at, end - at);
    if (tag.find("is_default_profile=\"true\"") == std::string::npos) continue;
    const std::size_t name = tag.find("profile_name=\"");
    if (name == std::string::npos) continue;
    const std::size_t first = name + 14;
    const std::size_t last = tag.find('"', first);
    if (last != std::string::npos) return tag.substr(first, last - first);
  }
  return "";
}

class FastParticipant final : public ParticipantBackend {
 public:
  FastParticipant(const TransportConfig& config, EventLog& events) : events_(events) {
    auto* factory = dds::DomainParticipantFactory::get_instance();
    std::string profile = config.profile_file;
    if (profile.empty()) {
      const char* env = std::getenv("FASTRTPS_DEFAULT_PROFILES_FILE");
      if (env != nullptr && *env != '\0') {
        profile = env;
        TransportConfig check = config;
        check.profile_file = profile;
        validate(check);
      }
    }
    // Fast DDS 2.9 takes the factory's default participant QoS from the XML
    // default profile only when it resets that QoS, and loads its own default
    // file once (load_profiles). So: the vendor's file first, then this one,
    // then the reset. Without the reset a profile's transports, peers and
    // socket buffers were silently ignored. The factory is the process's:
    // the QoS is taken from the file's default participant profile by name
    // (a file parsed before is not parsed again, so the factory's default
    // may be another file's), and the factory's default goes back to the
    // vendor's afterwards, so a later participant without a profile does
    // not inherit this one's.
    const dds::DomainParticipantQos& vendor_default = vendor_default_participant_qos(*factory);
    dds::DomainParticipantQos qos = vendor_default;
    if (!profile.empty()) {
      if (factory->load_XML_profiles_file(profile) != ReturnCode_t::RETCODE_OK) {
        throw ConfigError("DDS profile '" + profile +
                          "': Fast DDS could not parse it (malformed XML profile)");
      }
      const std::string name = default_participant_profile(profile);
      if (name.empty() ||
          factory->get_participant_qos_from_profile(name, qos) != ReturnCode_t::RETCODE_OK) {
        factory->set_default_participant_qos(dds::PARTICIPANT_QOS_DEFAULT);
        qos = factory->get_default_participant_qos();
      }
      factory->set_default_participant_qos(vendor_default);
    }
    qos.name(config.participant_name);
    // Socket buffers the size of a burst of large samples, unless a profile
    // chose them (docs/design/mixed-vendor-load.md): with the system's
    // default 208 KiB a Cyclone writer's 250 KB DeformationState overflowed
    // the receive buffer and took DevicePoses on the same socket with it.
    auto& transport = qos.transport();
    if (transport.listen_socket_buffer_size == 0) {
      transport.listen_socket_buffer_size = kSocketBufferBytes;
    }
    if (transport.send_socket_buffer_size == 0)
      transport.send_socket_buffer_size = kSocketBufferBytes;
    if (!config.security_dir.empty()) {
      // The builtin plugins of DDS Security 1.1 (Fast DDS 2.9 is built with them).
      const SecurityFiles f = security_files(config);
      auto& p = qos.properties().properties();
      const std::string auth = "dds.sec.auth.builtin.PKI-DH.";
      const std::string access = "dds.sec.access.builtin.Access-Permissions.";
      p.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
      p.emplace_back(auth + "identity_ca", "file://" + f.ca_cert);
      p.emplace_back(auth + "identity_certificate", "file://" + f.cert);
      p.emplace_back(auth + "private_key", "file://" + f.key);
      p.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
      p.emplace_back(access + "permissions_ca", "file://" + f.ca_cert);
      p.emplace_back(access + "governance", "file://" + f.governance);
      p.emplace_back(access + "permissions", "file://" + f.permissions);
      p.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
    }
    participant_ = factory->create_participant(config.domain_id, qos);
    if (participant_ == nullptr) {
      throw std::runtime_error("Fast DDS could not create a participant in domain " +
                               std::to_string(config.domain_id));
    }
    dds::PublisherQos pub_qos = participant_->get_default_publisher_qos();
    dds::SubscriberQos sub_qos = participant_->get_default_subscriber_qos();
    if (!config.partition.empty()) {
      pub_qos.partition().push_back(config.partition.c_str());
      sub_qos.partition().push_back(config.partition.c_str());
    }
    publisher_ = participant_->create_publisher(pub_qos);
    subscriber_ = participant_->create_subscriber(sub_qos);
  }

  ~FastParticipant() override {
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }

  std::unique_ptr<WriterBackend> create_writer(const EndpointSpec& spec) override {
    auto [topic, max_bytes] = topic_for(spec);
    return std::make_unique<FastWriter>(*publisher_, *topic, spec.qos, max_bytes, events_);
  }

  std::unique_ptr<ReaderBackend> create_reader(const EndpointSpec& spec,
                                               SampleSink* sink) override {
    auto [topic, max_bytes] = topic_for(spec);
    return std::make_unique<FastReader>(*subscriber_, *topic, *spec.type, spec.qos, max_bytes, sink,
                                        events_);
  }

  std::unique_ptr<ReaderBackend> create_raw_reader(const EndpointSpec& spec,
                                                   RawSampleSink* sink) override {
    auto [topic, max_bytes] = topic_for(spec, true);
    return std::make_unique<FastReader>(*subscriber_, *topic, *spec.type, spec.qos, max_bytes,
                                        nullptr, events_, sink);
  }
  bool raw_bytes_as_received() const override { return true; }

 private:
  std::pair<dds::Topic*, std::uint32_t> topic_for(const EndpointSpec& spec, bool raw = false) {
    std::lock_guard lock(mutex_);
    auto type_it = types_.find(spec.type->type_name);
    if (type_it != types_.end() && raw_types_.count(spec.type->type_name) != (raw ? 1U : 0U)) {
      throw std::runtime_error(std::string("Fast DDS participant: type ") + spec.type->type_name +
                               " is carried both typed and raw");
    }
    if (type_it == types_.end()) {
      if (raw) raw_types_.insert(spec.type->type_name);
      dds::TypeSupport support(raw ? static_cast<dds::TopicDataType*>(new RawTopicType(*spec.type))
                                   : static_cast<dds::TopicDataType*>(spec.type->make_fast_type()));
      if (support.register_type(participant_) != ReturnCode_t::RETCODE_OK) {
        throw std::runtime_error(std::string("Fast DDS refused type ") + spec.type->type_name);
      }
      type_it = types_.emplace(spec.type->type_name, support).first;
    }
    auto topic_it = topics_.find(spec.topic_name);
    if (topic_it == topics_.end()) {
      dds::Topic* topic =
          participant_->create_topic(spec.topic_name, spec.type->type_name, dds::TOPIC_QOS_DEFAULT);
      if (topic == nullptr) throw std::runtime_error("Fast DDS refused topic " + spec.topic_name);
      topic_it = topics_.emplace(spec.topic_name, topic).first;
    }
    return {topic_it->second, type_it->second->m_typeSize};
  }

  EventLog& events_;
  dds::DomainParticipant* participant_ = nullptr;
  dds::Publisher* publisher_ = nullptr;
  dds::Subscriber* subscriber_ = nullptr;
  std::mutex mutex_;
  std::map<std::string, dds::TypeSupport> types_;
  std::set<std::string> raw_types_;
  std::map<std::string, dds::Topic*> topics_;
};

}  // namespace

std::unique_ptr<ParticipantBackend> make_fast_backend(const TransportConfig& config,
                                                      EventLog& events) {
  return std::make_unique<FastParticipant>(config, events);
}

}  // namespace fahr::common::detail
