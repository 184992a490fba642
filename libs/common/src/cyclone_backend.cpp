// Cyclone DDS 0.10 backend. Topics and discovery use idlc's descriptors;
// the bytes are the fastddsgen CDR serialisation, handed to Cyclone as
// serialized data (dds_writecdr / dds_takecdr). Both vendors thus put the
// same XCDR1 bytes on the wire and the application sees one C++ type.
// Fast DDS first: Cyclone's ddsi headers define PID_* macros that break
// Fast DDS's ParameterTypes.hpp if they come before it.
#include <fastdds/dds/topic/TopicDataType.hpp>
// (keep this blank line: it stops clang-format from reordering the groups)

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <dds/ddsi/ddsi_sertype.h>
#include <dds/security/dds_security_api_defs.h>

#include <array>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include "backends.h"
#include "fahr/common/cdr_bytes.h"
#include "fahr/common/clock.h"
#include "fahr/common/config_error.h"

namespace fahr::common::detail {
namespace {

using eprosima::fastdds::dds::TopicDataType;
using eprosima::fastrtps::rtps::SerializedPayload_t;

#ifndef FAHR_CYCLONE_SECURITY_PLUGIN_DIR
#define FAHR_CYCLONE_SECURITY_PLUGIN_DIR "/usr/lib/x86_64-linux-gnu/libddsc0debian"
#endif
// Where Debian's cyclonedds package installs the security plugins.
constexpr const char* kCycloneSecurityPluginDir = FAHR_CYCLONE_SECURITY_PLUGIN_DIR;

// Partition of the endpoints that discover a type's sertype; no service
// ever uses it, so they match nothing outside this participant.
constexpr const char* kProbePartition = "__fahr_sertype_probe";

std::string retcode_text(dds_return_t rc) {
  return dds_strretcode(rc);
}

dds_qos_t* make_qos(const QosProfile& profile) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos,
                       profile.reliability == Reliability::kReliable ? DDS_RELIABILITY_RELIABLE
                                                                     : DDS_RELIABILITY_BEST_EFFORT,
                       DDS_MSECS(100));
  dds_qset_durability(qos, profile.durability == Durability::kTransientLocal
                               ? DDS_DURABILITY_TRANSIENT_LOCAL
                               : DDS_DURABILITY_VOLATILE);
  if (profile.history_depth == 0) {
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
  } else {
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, profile.history_depth);
  }
  if (profile.deadline.count() > 0) dds_qset_deadline(qos, profile.deadline.count());
  if (profile.liveliness_lease.count() > 0) {
    dds_qset_liveliness(qos, DDS_LIVELINESS_MANUAL_BY_TOPIC, profile.liveliness_lease.count());
  }
  if (profile.lifespan.count() > 0) dds_qset_lifespan(qos, profile.lifespan.count());
  return qos;
}

// What every Cyclone endpoint shares: its topic name, the event log, and
// the last cumulative count of each status. Cyclone's listener passes a
// total_count_change that keeps growing until the status is read, so the
// change is computed here from the cumulative totals.
struct EndpointContext {
  std::string topic;
  EventLog* events = nullptr;
  std::atomic<int> matched{0};
  std::array<std::int64_t, kEventKindCount> last_total{};
};

TransportEvent make_event(EventKind kind, EndpointContext& ctx, std::int64_t total) {
  TransportEvent event;
  event.time_ns = wall_now_ns();
  event.kind = kind;
  set_event_topic(event, ctx.topic);
  auto& last = ctx.last_total[static_cast<std::size_t>(kind)];
  event.total_count = static_cast<std::int32_t>(total);
  event.total_count_change = static_cast<std::int32_t>(total - last);
  last = total;
  return event;
}

void on_publication_matched(dds_entity_t, const dds_publication_matched_status_t s, void* arg) {
  auto* ctx = static_cast<EndpointContext*>(arg);
  ctx->matched.store(static_cast<int>(s.current_count));
  auto event = make_event(EventKind::kPublicationMatched, *ctx, s.total_count);
  event.total_count_change = s.current_count_change;  // +1 matched, -1 unmatched
  event.current_count = static_cast<std::int32_t>(s.current_count);
  ctx->events->record(event);
}
void on_subscription_matched(dds_entity_t, const dds_subscription_matched_status_t s, void* arg) {
  auto* ctx = static_cast<EndpointContext*>(arg);
  ctx->matched.store(static_cast<int>(s.current_count));
  auto event = make_event(EventKind::kSubscriptionMatched, *ctx, s.total_count);
  event.total_count_change = s.current_count_change;  // +1 matched, -1 unmatched
  event.current_count = static_cast<std::int32_t>(s.current_count);
  ctx->events->record(event);
}
void on_offered_deadline_missed(dds_entity_t, const dds_offered_deadline_missed_status_t s,
                                void* arg) {
  auto* ctx = static_cast<EndpointContext*>(arg);
  ctx->events->record(make_event(EventKind::kOfferedDeadlineMissed, *ctx, s.total_count));
}
void on_requested_deadline_missed(dds_entity_t, const dds_requested_deadline_missed_status_t s,
                                  void* arg) {
  auto* ctx = static_cast<EndpointContext*>(arg);
  ctx->events->record(make_event(EventKind::kRequestedDeadlineMissed, *ctx, s.total_count));
}
void on_offered_incompatible_qos(dds_entity_t, const dds_offered_incompatible_qos_status_t s,
                                 void* arg) {
  auto* ctx = static_cast<EndpointContext*>(arg);
  ctx->events->record(make_event(EventKind::kOfferedIncompatibleQos, *ctx, s.total_count));
}
void on_requested_incompatible_qos(dds_entity_t, const dds_requested_incompatible_qos_status_t s,
                                   void* arg) {
  auto* ctx = static_cast<EndpointContext*>(arg);
  ctx->events->record(make_event(EventKind::kRequestedIncompatibleQos, *ctx, s.total_count));
}
void on_liveliness_lost(dds_entity_t, const dds_liveliness_lost_status_t s, void* arg) {
  auto* ctx = static_cast<EndpointContext*>(arg);
  ctx->events->record(make_event(EventKind::kLivelinessLost, *ctx, s.total_count));
}
void on_liveliness_changed(dds_entity_t, const dds_liveliness_changed_status_t s, void* arg) {
  auto* ctx = static_cast<EndpointContext*>(arg);
  auto event = make_event(EventKind::kLivelinessChanged, *ctx, s.alive_count + s.not_alive_count);
  event.current_count = static_cast<std::int32_t>(s.alive_count);
  event.not_alive_count = static_cast<std::int32_t>(s.not_alive_count);
  ctx->events->record(event);
}
void on_sample_lost(dds_entity_t, const dds_sample_lost_status_t s, void* arg) {
  auto* ctx = static_cast<EndpointContext*>(arg);
  ctx->events->record(make_event(EventKind::kSampleLost, *ctx, s.total_count));
}
void on_sample_rejected(dds_entity_t, const dds_sample_rejected_status_t s, void* arg) {
  auto* ctx = static_cast<EndpointContext*>(arg);
  ctx->events->record(make_event(EventKind::kSampleRejected, *ctx, s.total_count));
}

class CycloneWriter final : public WriterBackend {
 public:
  CycloneWriter(dds_entity_t publisher, dds_entity_t topic, const std::string& topic_name,
                const ddsi_sertype* sertype, const TypeSupport& type, const QosProfile& profile,
                EventLog& events)
      : sertype_(sertype), fast_type_(static_cast<TopicDataType*>(type.make_fast_type())) {
    ctx_.topic = topic_name;
    ctx_.events = &events;
    dds_listener_t* listener = dds_create_listener(&ctx_);
    dds_lset_publication_matched(listener, on_publication_matched);
    dds_lset_offered_deadline_missed(listener, on_offered_deadline_missed);
    dds_lset_offered_incompatible_qos(listener, on_offered_incompatible_qos);
    dds_lset_liveliness_lost(listener, on_liveliness_lost);
    dds_qos_t* qos = make_qos(profile);
    writer_ = dds_create_writer(publisher, topic, qos, listener);
    dds_delete_qos(qos);
    dds_delete_listener(listener);
    if (writer_ < 0)
      throw std::runtime_error("Cyclone DDS refused a writer on " + topic_name + ": " +
                               retcode_text(writer_));
  }
  ~CycloneWriter() override { dds_delete(writer_); }

  bool write(const void* sample, std::int64_t source_time_ns) override {
    void* data = const_cast<void*>(sample);
    const std::uint32_t size = fast_type_->getSerializedSizeProvider(data)();
    if (payload_.max_size < size) payload_.reserve(size);  // grows to the largest sample once
    if (!fast_type_->serialize(data, &payload_)) return false;
    ddsrt_iovec_t iov{payload_.data, payload_.length};
    ddsi_serdata* serdata = ddsi_serdata_from_ser_iov(sertype_, SDK_DATA, 1, &iov, payload_.length);
    if (serdata == nullptr) return false;
    serdata->timestamp.v = source_time_ns;
    return dds_writecdr(writer_, serdata) >= 0;  // takes the reference
  }
  void assert_liveliness() override { dds_assert_liveliness(writer_); }
  int matched_readers() const override { return ctx_.matched.load(); }
  bool wait_for_acks(std::chrono::nanoseconds timeout) override {
    return dds_wait_for_acks(writer_, timeout.count()) == DDS_RETCODE_OK;
  }

 private:
  EndpointContext ctx_;
  const ddsi_sertype* sertype_;
  std::unique_ptr<TopicDataType> fast_type_;
  SerializedPayload_t payload_;
  dds_entity_t writer_ = 0;
};

class CycloneReader final : public ReaderBackend {
 public:
  // With `raw_sink` set the reader hands over Cyclone's serialized bytes
  // (encapsulation header included) instead of typed samples.
  CycloneReader(dds_entity_t subscriber, dds_entity_t topic, const std::string& topic_name,
                const TypeSupport& type, const QosProfile& profile, SampleSink* sink,
                EventLog& events, RawSampleSink* raw_sink = nullptr)
      : type_(type),
        fast_type_(static_cast<TopicDataType*>(type.make_fast_type())),
        sink_(sink),
        raw_sink_(raw_sink),
        scratch_(type.new_sample()) {
    ctx_.topic = topic_name;
    ctx_.events = &events;
    dds_listener_t* listener = dds_create_listener(this);
    dds_lset_data_available(listener, on_data_available);
    dds_lset_subscription_matched_arg(listener, on_subscription_matched, &ctx_, false);
    dds_lset_requested_deadline_missed_arg(listener, on_requested_deadline_missed, &ctx_, false);
    dds_lset_requested_incompatible_qos_arg(listener, on_requested_incompatible_qos, &ctx_, false);
    dds_lset_liveliness_changed_arg(listener, on_liveliness_changed, &ctx_, false);
    dds_lset_sample_lost_arg(listener, on_sample_lost, &ctx_, false);
    dds_lset_sample_rejected_arg(listener, on_sample_rejected, &ctx_, false);
    dds_qos_t* qos = make_qos(profile);
    reader_ = dds_create_reader(subscriber, topic, qos, listener);
    dds_delete_qos(qos);
    dds_delete_listener(listener);
    if (reader_ < 0)
      throw std::runtime_error("Cyclone DDS refused a reader on " + topic_name + ": " +
                               retcode_text(reader_));
  }
  ~CycloneReader() override {
    dds_delete(reader_);  // waits for a running listener to return
    type_.delete_sample(scratch_);
  }
  int matched_writers() const override { return ctx_.matched.load(); }

 private:
  static void on_data_available(dds_entity_t reader, void* arg) {
    static_cast<CycloneReader*>(arg)->take_all(reader);
  }

  void take_all(dds_entity_t reader) {
    ddsi_serdata* serdata = nullptr;
    dds_sample_info_t info;
    while (dds_takecdr(reader, &serdata, 1, &info, DDS_ANY_STATE) == 1) {
      if (info.valid_data) deliver(*serdata, info.source_timestamp, info.publication_handle);
      ddsi_serdata_unref(serdata);
    }
  }

  void deliver(const ddsi_serdata& serdata, dds_time_t source_time_ns, std::uint64_t source_key) {
    const std::uint32_t size = ddsi_serdata_size(&serdata);
    ddsrt_iovec_t ref{};
    ddsi_serdata* held = ddsi_serdata_to_ser_ref(&serdata, 0, size, &ref);
    if (raw_sink_ != nullptr) {
      raw_sink_->deliver_raw(static_cast<const std::uint8_t*>(ref.iov_base), ref.iov_len,
                             source_time_ns);
      ddsi_serdata_to_ser_unref(held, &ref);
      return;
    }
    // Cyclone's bytes, borrowed by the fastcdr decoder.
    const bool ok = decode_cdr(
        *fast_type_, {static_cast<const std::uint8_t*>(ref.iov_base), ref.iov_len}, scratch_);
    ddsi_serdata_to_ser_unref(held, &ref);
    if (ok) sink_->deliver(scratch_, source_time_ns, source_key);
  }

  EndpointContext ctx_;
  const TypeSupport& type_;
  std::unique_ptr<TopicDataType> fast_type_;
  SampleSink* sink_;
  RawSampleSink* raw_sink_;
  void* scratch_;
  dds_entity_t reader_ = 0;
};

class CycloneParticipant final : public ParticipantBackend {
 public:
  CycloneParticipant(const TransportConfig& config, EventLog& events) : events_(events) {
    if (!config.profile_file.empty()) create_domain(config);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_entity_name(qos, config.participant_name.c_str());
    if (!config.security_dir.empty()) set_security(config, qos);
    participant_ = dds_create_participant(config.domain_id, qos, nullptr);
    dds_delete_qos(qos);
    if (participant_ < 0) {
      throw ConfigError("Cyclone DDS could not create a participant in domain " +
                        std::to_string(config.domain_id) + ": " + retcode_text(participant_) +
                        " (check CYCLONEDDS_URI or the DDS profile)");
    }
    dds_qos_t* group_qos = dds_create_qos();
    if (!config.partition.empty()) dds_qset_partition1(group_qos, config.partition.c_str());
    publisher_ = dds_create_publisher(participant_, group_qos, nullptr);
    subscriber_ = dds_create_subscriber(participant_, group_qos, nullptr);
    dds_delete_qos(group_qos);
  }
  ~CycloneParticipant() override {
    for (auto& [name, sertype] : sertypes_) ddsi_sertype_unref(const_cast<ddsi_sertype*>(sertype));
    dds_delete(participant_);
    if (domain_ > 0) dds_delete(domain_);
  }

  std::unique_ptr<WriterBackend> create_writer(const EndpointSpec& spec) override {
    std::lock_guard lock(mutex_);
    const dds_entity_t topic = topic_for(spec);
    return std::make_unique<CycloneWriter>(publisher_, topic, spec.topic_name,
                                           sertype_for(spec, topic), *spec.type, spec.qos, events_);
  }

  std::unique_ptr<ReaderBackend> create_reader(const EndpointSpec& spec,
                                               SampleSink* sink) override {
    std::lock_guard lock(mutex_);
    const dds_entity_t topic = topic_for(spec);
    return std::make_unique<CycloneReader>(subscriber_, topic, spec.topic_name, *spec.type,
                                           spec.qos, sink, events_);
  }

  std::unique_ptr<ReaderBackend> create_raw_reader(const EndpointSpec& spec,
                                                   RawSampleSink* sink) override {
    std::lock_guard lock(mutex_);
    const dds_entity_t topic = topic_for(spec);
    return std::make_unique<CycloneReader>(subscriber_, topic, spec.topic_name, *spec.type,
                                           spec.qos, nullptr, events_, sink);
  }
  bool raw_bytes_as_received() const override { return true; }

 private:
  // DDS Security 1.1's builtin plugins as Debian installs them (Cyclone
  // 0.10: dds_security_auth, dds_security_ac, dds_security_crypto, outside
  // the loader's path), configured by the participant's properties.
  static void set_security(const TransportConfig& config, dds_qos_t* qos) {
    const SecurityFiles f = security_files(config);
    const std::string plugins = kCycloneSecurityPluginDir;
    const auto prop = [qos](const char* name, const std::string& value) {
      dds_qset_prop(qos, name, value.c_str());
    };
    prop(DDS_SEC_PROP_AUTH_LIBRARY_PATH, plugins + "/libdds_security_auth.so");
    prop(DDS_SEC_PROP_AUTH_LIBRARY_INIT, "init_authentication");
    prop(DDS_SEC_PROP_AUTH_LIBRARY_FINALIZE, "finalize_authentication");
    prop(DDS_SEC_PROP_CRYPTO_LIBRARY_PATH, plugins + "/libdds_security_crypto.so");
    prop(DDS_SEC_PROP_CRYPTO_LIBRARY_INIT, "init_crypto");
    prop(DDS_SEC_PROP_CRYPTO_LIBRARY_FINALIZE, "finalize_crypto");
    prop(DDS_SEC_PROP_ACCESS_LIBRARY_PATH, plugins + "/libdds_security_ac.so");
    prop(DDS_SEC_PROP_ACCESS_LIBRARY_INIT, "init_access_control");
    prop(DDS_SEC_PROP_ACCESS_LIBRARY_FINALIZE, "finalize_access_control");
    prop(DDS_SEC_PROP_AUTH_IDENTITY_CA, "file:" + f.ca_cert);
    prop(DDS_SEC_PROP_AUTH_IDENTITY_CERT, "file:" + f.cert);
    prop(DDS_SEC_PROP_AUTH_PRIV_KEY, "file:" + f.key);
    prop(DDS_SEC_PROP_ACCESS_PERMISSIONS_CA, "file:" + f.ca_cert);
    prop(DDS_SEC_PROP_ACCESS_GOVERNANCE, "file:" + f.governance);
    prop(DDS_SEC_PROP_ACCESS_PERMISSIONS, "file:" + f.permissions);
  }

  void create_domain(const TransportConfig& config) {
    std::ifstream in(config.profile_file);
    std::stringstream text;
    text << in.rdbuf();
    domain_ = dds_create_domain(config.domain_id, text.str().c_str());
    // Another participant of this process may have created the domain
    // already; its configuration then stands.
    if (domain_ < 0 && domain_ != DDS_RETCODE_PRECONDITION_NOT_MET) {
      throw ConfigError("DDS profile '" + config.profile_file + "': Cyclone DDS refused it (" +
                        retcode_text(domain_) + "; malformed configuration?)");
    }
  }

  dds_entity_t topic_for(const EndpointSpec& spec) {
    auto it = topics_.find(spec.topic_name);
    if (it != topics_.end()) return it->second;
    const auto* descriptor =
        static_cast<const dds_topic_descriptor_t*>(spec.type->cyclone_descriptor);
    const dds_entity_t topic =
        dds_create_topic(participant_, descriptor, spec.topic_name.c_str(), nullptr, nullptr);
    if (topic < 0)
      throw std::runtime_error("Cyclone DDS refused topic " + spec.topic_name + ": " +
                               retcode_text(topic));
    topics_.emplace(spec.topic_name, topic);
    return topic;
  }

  // Cyclone 0.10 has no public call returning a topic's sertype, and
  // dds_writecdr needs serdata of exactly that sertype. So write one zeroed
  // sample through a private partition to a local reader and take the
  // sertype from the serialized sample that arrives.
  const ddsi_sertype* sertype_for(const EndpointSpec& spec, dds_entity_t topic) {
    auto it = sertypes_.find(spec.topic_name);
    if (it != sertypes_.end()) return it->second;
    dds_qos_t* group_qos = dds_create_qos();
    dds_qset_partition1(group_qos, kProbePartition);
    const dds_entity_t probe_publisher = dds_create_publisher(participant_, group_qos, nullptr);
    const dds_entity_t probe_subscriber = dds_create_subscriber(participant_, group_qos, nullptr);
    dds_delete_qos(group_qos);
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_MSECS(100));
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
    const dds_entity_t reader = dds_create_reader(probe_subscriber, topic, qos, nullptr);
    const dds_entity_t writer = dds_create_writer(probe_publisher, topic, qos, nullptr);
    dds_delete_qos(qos);
    if (writer < 0 || reader < 0) {
      // DDS Security: this participant's permissions do not allow it.
      const dds_return_t rc = writer < 0 ? writer : reader;
      dds_delete(probe_publisher);
      dds_delete(probe_subscriber);
      throw std::runtime_error("Cyclone DDS refused a writer of " + spec.topic_name + ": " +
                               retcode_text(rc));
    }
    const auto* descriptor =
        static_cast<const dds_topic_descriptor_t*>(spec.type->cyclone_descriptor);
    void* zero = std::calloc(1, descriptor->m_size);
    dds_write(writer, zero);
    std::free(zero);
    ddsi_serdata* serdata = nullptr;
    dds_sample_info_t info;
    const ddsi_sertype* sertype = nullptr;
    for (int attempt = 0; attempt < 200 && sertype == nullptr; ++attempt) {
      if (dds_takecdr(reader, &serdata, 1, &info, DDS_ANY_STATE) == 1) {
        sertype = ddsi_sertype_ref(serdata->type);
        ddsi_serdata_unref(serdata);
      } else {
        dds_sleepfor(DDS_MSECS(1));
      }
    }
    dds_delete(probe_publisher);
    dds_delete(probe_subscriber);
    if (sertype == nullptr)
      throw std::runtime_error("Cyclone DDS: could not obtain the sertype of " + spec.topic_name);
    sertypes_.emplace(spec.topic_name, sertype);
    return sertype;
  }

  EventLog& events_;
  dds_entity_t domain_ = 0;
  dds_entity_t participant_ = 0;
  dds_entity_t publisher_ = 0;
  dds_entity_t subscriber_ = 0;
  std::mutex mutex_;
  std::map<std::string, dds_entity_t> topics_;
  std::map<std::string, const ddsi_sertype*> sertypes_;
};

}  // namespace

std::unique_ptr<ParticipantBackend> make_cyclone_backend(const TransportConfig& config,
                                                         EventLog& events) {
  return std::make_unique<CycloneParticipant>(config, events);
}

}  // namespace fahr::common::detail
