// In-process bus: services in one process exchange samples by copy, through
// the same Publisher/Subscriber API, with no DDS at all. Matching follows
// the DDS rules that matter here (same domain, partition and topic; a best
// effort writer does not serve a reliable reader); transient-local writers
// replay their newest sample to late readers. Deadlines, liveliness and
// lifespan are not simulated: use a DDS vendor to test them.
#include <algorithm>
#include <map>
#include <memory>
#include <mutex>
#include <shared_mutex>
#include <vector>

#include "backends.h"
#include "fahr/common/clock.h"

namespace fahr::common::detail {
namespace {

class InProcessWriter;

struct InProcessReaderEntry {
  SampleSink* sink;
  QosProfile qos;
  EventLog* events;
};

// One topic of one domain and partition. Deliveries take the shared lock;
// only creating or deleting endpoints (start-up, shutdown) takes it
// exclusively, so a running loop never waits on another writer.
struct BusTopic {
  std::shared_mutex mutex;
  std::vector<InProcessReaderEntry*> readers;
  std::vector<InProcessWriter*> writers;
};

class Bus {
 public:
  static Bus& instance() {
    static Bus bus;
    return bus;
  }
  std::shared_ptr<BusTopic> topic(std::uint32_t domain, const std::string& partition,
                                  const std::string& name) {
    std::lock_guard lock(mutex_);
    auto& slot = topics_[Key{domain, partition, name}];
    if (!slot) slot = std::make_shared<BusTopic>();
    return slot;
  }

 private:
  struct Key {
    std::uint32_t domain;
    std::string partition;
    std::string name;
    bool operator<(const Key& other) const {
      return std::tie(domain, partition, name) <
             std::tie(other.domain, other.partition, other.name);
    }
  };
  std::mutex mutex_;
  std::map<Key, std::shared_ptr<BusTopic>> topics_;
};

bool compatible(const QosProfile& writer, const QosProfile& reader) {
  if (reader.reliability == Reliability::kReliable &&
      writer.reliability == Reliability::kBestEffort)
    return false;
  if (reader.durability == Durability::kTransientLocal &&
      writer.durability == Durability::kVolatile)
    return false;
  return true;
}

void record_match(EventLog& events, EventKind kind, const std::string& topic, int change) {
  TransportEvent event;
  event.time_ns = wall_now_ns();
  event.kind = kind;
  set_event_topic(event, topic);
  event.total_count_change = change;
  events.record(event);
}

class InProcessWriter final : public WriterBackend {
 public:
  InProcessWriter(std::shared_ptr<BusTopic> topic, const EndpointSpec& spec, EventLog& events)
      : topic_(std::move(topic)),
        type_(*spec.type),
        qos_(spec.qos),
        name_(spec.topic_name),
        events_(events) {
    if (qos_.durability == Durability::kTransientLocal) latched_ = type_.new_sample();
    std::unique_lock lock(topic_->mutex);
    topic_->writers.push_back(this);
    for (auto* reader : topic_->readers) match(*reader, +1);
  }
  ~InProcessWriter() override {
    std::unique_lock lock(topic_->mutex);
    std::erase(topic_->writers, this);
    for (auto* reader : topic_->readers) match(*reader, -1);
    lock.unlock();
    if (latched_ != nullptr) type_.delete_sample(latched_);
  }

  bool write(const void* sample, std::int64_t source_time_ns) override {
    std::shared_lock lock(topic_->mutex);
    if (latched_ != nullptr) {
      type_.copy_sample(latched_, sample);
      has_latched_ = true;
      latched_time_ns_ = source_time_ns;
    }
    for (auto* reader : topic_->readers) {
      if (compatible(qos_, reader->qos)) reader->sink->deliver(sample, source_time_ns, key());
    }
    return true;
  }
  void assert_liveliness() override {}
  int matched_readers() const override {
    std::shared_lock lock(topic_->mutex);
    return static_cast<int>(std::count_if(topic_->readers.begin(), topic_->readers.end(),
                                          [&](const auto* r) { return compatible(qos_, r->qos); }));
  }

  // Called with the topic locked exclusively.
  void match(InProcessReaderEntry& reader, int change) {
    if (!compatible(qos_, reader.qos)) {
      if (change > 0) {
        record_match(events_, EventKind::kOfferedIncompatibleQos, name_, 1);
        record_match(*reader.events, EventKind::kRequestedIncompatibleQos, name_, 1);
      }
      return;
    }
    record_match(events_, EventKind::kPublicationMatched, name_, change);
    record_match(*reader.events, EventKind::kSubscriptionMatched, name_, change);
    if (change > 0 && has_latched_ && reader.qos.durability == Durability::kTransientLocal) {
      reader.sink->deliver(latched_, latched_time_ns_, key());
    }
  }
  const QosProfile& qos() const { return qos_; }
  // The writer's identity on the bus: its address.
  std::uint64_t key() const { return reinterpret_cast<std::uintptr_t>(this); }

 private:
  std::shared_ptr<BusTopic> topic_;
  const TypeSupport& type_;
  QosProfile qos_;
  std::string name_;
  EventLog& events_;
  void* latched_ = nullptr;
  bool has_latched_ = false;
  std::int64_t latched_time_ns_ = 0;
};

class InProcessReader final : public ReaderBackend {
 public:
  InProcessReader(std::shared_ptr<BusTopic> topic, const EndpointSpec& spec, SampleSink* sink,
                  EventLog& events)
      : topic_(std::move(topic)), entry_{sink, spec.qos, &events} {
    std::unique_lock lock(topic_->mutex);
    topic_->readers.push_back(&entry_);
    for (auto* writer : topic_->writers) writer->match(entry_, +1);
  }
  ~InProcessReader() override {
    std::unique_lock lock(topic_->mutex);
    std::erase(topic_->readers, &entry_);
    for (auto* writer : topic_->writers) writer->match(entry_, -1);
  }
  int matched_writers() const override {
    std::shared_lock lock(topic_->mutex);
    return static_cast<int>(
        std::count_if(topic_->writers.begin(), topic_->writers.end(),
                      [&](const auto* w) { return compatible(w->qos(), entry_.qos); }));
  }

 private:
  std::shared_ptr<BusTopic> topic_;
  InProcessReaderEntry entry_;
};

class InProcessParticipant final : public ParticipantBackend {
 public:
  InProcessParticipant(const TransportConfig& config, EventLog& events)
      : config_(config), events_(events) {}

  std::unique_ptr<WriterBackend> create_writer(const EndpointSpec& spec) override {
    return std::make_unique<InProcessWriter>(topic(spec), spec, events_);
  }
  std::unique_ptr<ReaderBackend> create_reader(const EndpointSpec& spec,
                                               SampleSink* sink) override {
    return std::make_unique<InProcessReader>(topic(spec), spec, sink, events_);
  }

 private:
  std::shared_ptr<BusTopic> topic(const EndpointSpec& spec) {
    return Bus::instance().topic(config_.domain_id, config_.partition, spec.topic_name);
  }
  TransportConfig config_;
  EventLog& events_;
};

}  // namespace

std::unique_ptr<ParticipantBackend> make_inprocess_backend(const TransportConfig& config,
                                                           EventLog& events) {
  return std::make_unique<InProcessParticipant>(config, events);
}

}  // namespace fahr::common::detail
