// Raw subscriptions -> bounded queue -> MCAP writer thread.
#include "fahr/logger_service/recorder.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>

#include "fahr/common/cdr_bytes.h"
#include "fahr/common/clock.h"
#include "fahr/common/wire_header.h"
#include "fahr/idl/schemas.h"
#include "service_statusPubSubTypes.h"

namespace fahr::logger_service {
namespace {

using common::QosProfile;
using common::TopicRole;

// The recorder's reader QoS per role: what the writers offer, with a deep
// history, so every sample of a reliable topic is kept and a best-effort
// topic's loss is measured, not added to. No deadline or liveliness: the
// recorder judges nothing, and asks for nothing a writer must offer.
QosProfile recorder_qos(TopicRole role) {
  QosProfile qos = QosProfile::for_role(role);
  qos.deadline = {};
  qos.liveliness_lease = {};
  qos.lifespan = {};
  switch (role) {
    case TopicRole::kServoStream:
      qos.history_depth = 256;
      break;
    case TopicRole::kStateStream:
      qos.history_depth = 64;
      break;
    case TopicRole::kLatched:
      qos.history_depth = 16;
      break;
    case TopicRole::kReport:
      qos.history_depth = 200;
      break;
    case TopicRole::kLockstep:
      qos.history_depth = 64;
      break;
  }
  return qos;
}

std::string qos_text(const QosProfile& q) {
  std::string s = q.reliability == common::Reliability::kReliable ? "reliable" : "best_effort";
  s += q.durability == common::Durability::kTransientLocal ? ", transient_local" : ", volatile";
  s += q.history_depth == 0 ? ", keep_all" : ", keep_last " + std::to_string(q.history_depth);
  return s;
}

std::string role_text(TopicRole role) {
  switch (role) {
    case TopicRole::kServoStream:
      return "servo stream";
    case TopicRole::kStateStream:
      return "state stream";
    case TopicRole::kLatched:
      return "latched";
    case TopicRole::kReport:
      return "report";
    case TopicRole::kLockstep:
      return "lockstep";
  }
  return "?";
}

template <class T>
Recorder::Topic topic_of(const char* key_field) {
  Recorder::Topic t;
  t.name = std::string(common::TopicTraits<T>::kName);
  t.type_name = common::detail::type_support<T>().type_name;
  t.keyed = key_field != nullptr;
  t.key_field = key_field != nullptr ? key_field : "";
  t.writer_qos = QosProfile::for_role(common::TopicTraits<T>::kRole);
  t.qos = recorder_qos(common::TopicTraits<T>::kRole);
  t.role = role_text(common::TopicTraits<T>::kRole);
  const TopicRole role = common::TopicTraits<T>::kRole;
  t.always_queue = role != TopicRole::kServoStream && role != TopicRole::kStateStream;
  return t;
}

}  // namespace

Recorder::Recorder(common::Participant& participant, RecorderOptions options)
    : options_(std::move(options)), writer_(options_.mcap) {
  // Every fahr topic (libs/common topics.h), with its key field.
  topics_ = {
      topic_of<msg::DevicePose>("device_id"),     topic_of<msg::ForceCommand>("device_id"),
      topic_of<msg::ContactSet>("body_id"),       topic_of<msg::DeformationState>("body_id"),
      topic_of<msg::SceneDescription>("body_id"), topic_of<msg::ServiceStatus>("service_id"),
      topic_of<msg::ServiceEvents>("service_id"), topic_of<msg::SimClock>(nullptr),
      topic_of<msg::StepAck>("participant_id"),   topic_of<msg::GlotticView>("tool_body_id"),
  };
  writer_.open(options_.path);
  for (std::size_t i = 0; i < topics_.size(); ++i) {
    auto& t = topics_[i];
    if (options_.lockstep && !t.always_queue) {
      t.writer_qos.reliability = common::Reliability::kReliable;
      t.writer_qos.durability = common::Durability::kTransientLocal;
      t.writer_qos.history_depth = 8;
      t.qos.reliability = common::Reliability::kReliable;
      t.qos.durability = common::Durability::kTransientLocal;
      t.qos.history_depth = 64;
    }
    if (auto it = options_.decimate.find(t.name); it != options_.decimate.end()) {
      t.decimate = std::max<std::uint32_t>(1, it->second);
    }
    const std::string_view idl = idl::schema_of(t.type_name);
    t.schema_id = writer_.add_schema({0, t.type_name, "omgidl", std::string(idl)});
  }
  mcap::Metadata run{"fahr_run", {}};
  for (const auto& [k, v] : options_.run_metadata) run.values[k] = v;
  writer_.write_metadata(run);
  thread_ = std::thread([this] { run_writer(); });

  auto handler = [this](std::size_t index) {
    return [this, index](std::span<const std::uint8_t> cdr, std::int64_t source_ns) {
      on_sample(index, cdr, source_ns);
    };
  };
  using common::RawSubscriber;
  subscribers_.push_back(
      RawSubscriber::create<msg::DevicePose>(participant, topics_[0].qos, handler(0)));
  subscribers_.push_back(
      RawSubscriber::create<msg::ForceCommand>(participant, topics_[1].qos, handler(1)));
  subscribers_.push_back(
      RawSubscriber::create<msg::ContactSet>(participant, topics_[2].qos, handler(2)));
  subscribers_.push_back(
      RawSubscriber::create<msg::DeformationState>(participant, topics_[3].qos, handler(3)));
  subscribers_.push_back(
      RawSubscriber::create<msg::SceneDescription>(participant, topics_[4].qos, handler(4)));
  subscribers_.push_back(
      RawSubscriber::create<msg::ServiceStatus>(participant, topics_[5].qos, handler(5)));
  subscribers_.push_back(
      RawSubscriber::create<msg::ServiceEvents>(participant, topics_[6].qos, handler(6)));
  subscribers_.push_back(
      RawSubscriber::create<msg::SimClock>(participant, topics_[7].qos, handler(7)));
  subscribers_.push_back(
      RawSubscriber::create<msg::StepAck>(participant, topics_[8].qos, handler(8)));
  subscribers_.push_back(
      RawSubscriber::create<msg::GlotticView>(participant, topics_[9].qos, handler(9)));
}

Recorder::~Recorder() {
  try {
    stop();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_logger: closing the recording failed: %s\n", e.what());
  }
}

void Recorder::on_sample(std::size_t topic, std::span<const std::uint8_t> cdr,
                         std::int64_t /*dds_source_ns*/) {
  const std::int64_t receive_ns = common::wall_now_ns();
  const Topic& t = topics_[topic];
  const auto header = common::read_wire_header(cdr, t.keyed);
  if (!header) return;  // not fahr's CDR: nothing to account it to
  accounting_.on_receive(t.name, header->writer_id, header->seq);
  std::unique_lock lock(queue_mutex_);
  ++stats_.received;
  if (t.decimate > 1 && (header->seq - 1) % t.decimate != 0) {
    ++stats_.skipped;
    lock.unlock();
    accounting_.on_skipped(t.name, header->writer_id);
    return;
  }
  if (stopping_ || (!t.always_queue && queue_bytes_ + cdr.size() > options_.queue_bytes)) {
    ++stats_.dropped;
    lock.unlock();
    accounting_.on_drop(t.name, header->writer_id);
    return;
  }
  Item item;
  item.topic = topic;
  item.key = header->key;
  item.writer_id = header->writer_id;
  item.seq = header->seq;
  // The writer's source time is SampleHeader.source_time_ns, not the
  // vendor's source timestamp: Cyclone 0.10's dds_writecdr stamps its own
  // clock reading at the call (tens to hundreds of us after the header's).
  item.source_time_ns = header->source_time_ns;
  item.receive_time_ns = receive_ns;
  if (!spare_.empty()) {
    item.bytes = std::move(spare_.back());
    spare_.pop_back();
  }
  item.bytes.assign(cdr.begin(), cdr.end());
  queue_bytes_ += cdr.size();
  stats_.queue_peak_bytes = std::max(stats_.queue_peak_bytes, queue_bytes_);
  queue_.push_back(std::move(item));
  // The writer wakes every 20 ms on its own; a wake-up per sample would be
  // thousands of context switches a second on the services' cores. Only a
  // filling queue calls it early.
  const bool filling = queue_bytes_ > options_.queue_bytes / 4;
  lock.unlock();
  if (filling) queue_cv_.notify_one();
}

void Recorder::run_writer() {
  if (options_.writer_nice != 0) {
    // Linux: nice is per thread (PRIO_PROCESS with the thread's id).
    setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), options_.writer_nice);
  }
  std::deque<Item> batch;
  std::vector<std::vector<std::uint8_t>> used;
  while (true) {
    {
      std::unique_lock lock(queue_mutex_);
      queue_cv_.wait_for(lock, std::chrono::milliseconds(20),
                         [this] { return queue_bytes_ > options_.queue_bytes / 4 || stopping_; });
      // Give the buffers written last round back for reuse (a few).
      for (auto& b : used) {
        if (spare_.size() < 1024) spare_.push_back(std::move(b));
      }
      used.clear();
      if (queue_.empty() && stopping_) break;
      batch.swap(queue_);
    }
    std::size_t bytes = 0;
    for (Item& item : batch) {
      bytes += item.bytes.size();
      write_item(item);
      used.push_back(std::move(item.bytes));
    }
    batch.clear();
    {
      std::lock_guard lock(queue_mutex_);
      queue_bytes_ -= bytes;
    }
    writer_.poll(static_cast<std::uint64_t>(common::wall_now_ns()));
  }
}

void Recorder::write_item(Item& item) {
  if (options_.writer_delay.count() > 0) std::this_thread::sleep_for(options_.writer_delay);
  const Topic& t = topics_[item.topic];
  auto [it, fresh] = channels_.try_emplace({item.topic, item.key}, 0);
  if (fresh) {
    mcap::Channel channel;
    channel.schema_id = t.schema_id;
    channel.topic = t.name;
    channel.message_encoding = "cdr";
    channel.metadata["dds_type"] = t.type_name;
    channel.metadata["qos"] = qos_text(t.writer_qos);
    channel.metadata["recorder_qos"] = qos_text(t.qos);
    channel.metadata["role"] = t.role;
    if (t.keyed) channel.metadata["key"] = t.key_field + "=" + std::to_string(item.key);
    it->second = writer_.add_channel(std::move(channel));
  }
  writer_.write_message(it->second, static_cast<std::uint32_t>(item.seq),
                        static_cast<std::uint64_t>(item.receive_time_ns),
                        static_cast<std::uint64_t>(item.source_time_ns), item.bytes.data(),
                        item.bytes.size());
  accounting_.on_recorded(t.name, item.writer_id);
  {
    std::lock_guard lock(queue_mutex_);
    ++stats_.written;
    stats_.bytes += item.bytes.size();
  }
  if (t.name == common::TopicTraits<msg::ServiceStatus>::kName) note_status(item);
}

// A service's status: who it is, and the count each of its writers sent.
void Recorder::note_status(Item& item) {
  msg::ServiceStatus status;
  if (!common::decode_cdr<msg::ServiceStatusPubSubType>(item.bytes, status)) return;
  auto& info = services_[item.writer_id];
  info.name = status.service_name().to_string();
  info.host = status.host().to_string();
  info.vendor = status.dds_vendor().to_string();
  info.pid = status.pid();
  const std::string prefix = "sent ";
  for (const auto& m : status.metrics()) {
    const std::string name = m.name().to_string();
    if (name.rfind(prefix, 0) == 0) {
      accounting_.on_reported_sent(name.substr(prefix.size()), item.writer_id,
                                   static_cast<std::uint64_t>(m.value()));
    }
  }
}

void Recorder::write_closing_metadata() {
  mcap::Metadata services{"fahr_services", {}};
  for (const auto& [id, s] : services_) {
    services.values[s.name + " " + std::to_string(id)] =
        "host=" + s.host + " pid=" + std::to_string(s.pid) + " dds=" + s.vendor;
  }
  writer_.write_metadata(services);
  // "topic writer_id" -> "sent recorded gaps drops skipped leading_gaps"
  mcap::Metadata loss{"fahr_recording_loss", {}};
  for (const auto& t : accounting_.snapshot()) {
    loss.values[t.topic + " " + std::to_string(t.writer_id)] =
        std::to_string(t.sent()) + " " + std::to_string(t.recorded) + " " +
        std::to_string(t.total_gaps()) + " " + std::to_string(t.drops) + " " +
        std::to_string(t.skipped) + " " + std::to_string(t.leading_gaps());
  }
  writer_.write_metadata(loss);
}

void Recorder::stop() {
  if (stopped_) return;
  stopped_ = true;
  subscribers_.clear();  // no more deliveries
  {
    std::lock_guard lock(queue_mutex_);
    stopping_ = true;
  }
  queue_cv_.notify_one();
  if (thread_.joinable()) thread_.join();
  write_closing_metadata();
  writer_.close();
}

RecorderStats Recorder::stats() const {
  std::lock_guard lock(queue_mutex_);
  return stats_;
}

std::vector<std::string> Recorder::files() const {
  return writer_.files();
}

int Recorder::matched_writers() const {
  int n = 0;
  for (const auto& s : subscribers_) n += s->matched_writers();
  return n;
}

std::vector<std::pair<std::string, int>> Recorder::matched_by_topic() const {
  std::vector<std::pair<std::string, int>> out;
  out.reserve(subscribers_.size());
  for (std::size_t i = 0; i < subscribers_.size(); ++i)
    out.emplace_back(topics_[i].name, subscribers_[i]->matched_writers());
  return out;
}

bool Recorder::bytes_as_received() const {
  return !subscribers_.empty() && subscribers_.front()->bytes_as_received();
}

}  // namespace fahr::logger_service
