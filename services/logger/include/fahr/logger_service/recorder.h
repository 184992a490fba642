// The recorder: subscribes to every fahr topic as raw CDR bytes, hands each
// sample to a bounded queue on the vendor's thread (never the disk), and a
// writer thread of its own writes them to MCAP: one channel per topic and
// key, message encoding `cdr` with the bytes as they arrived, one omgidl
// schema per type (fahr::idl_schemas); log_time = receive time,
// publish_time = the writer's source time, sequence = SampleHeader.seq.
// Gaps, queue-overflow drops and each writer's sent count are kept per
// writer (loss_accounting.h) and written as Metadata when the file closes.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "fahr/common/participant.h"
#include "fahr/common/raw_subscriber.h"
#include "fahr/logger_service/loss_accounting.h"
#include "fahr/mcap/writer.h"

namespace fahr::logger_service {

struct RecorderOptions {
  std::string path;  // NAME.mcap (written as NAME.mcap.part until closed)
  mcap::WriterOptions mcap;
  // Bytes the queue may hold before samples of the streams (DevicePose,
  // ForceCommand, ContactSet, DeformationState) are dropped and counted;
  // reports, the scene and lockstep samples are always queued.
  std::size_t queue_bytes = 256u << 20;
  // Keep one sample in N of a topic (by sequence number); the others are
  // counted as skipped, not lost. Empty: keep everything.
  std::map<std::string, std::uint32_t> decimate;
  // Lockstep run: the services write the four streams reliable and
  // transient local (common::lockstep_output_qos); the recorder then reads
  // them reliably too, so nothing is lost and a replay has every step.
  bool lockstep = false;
  // Nice value of the writer thread (compression and disk): above 0 it
  // yields the CPU to the services' loops on a shared machine, its queue
  // absorbing the delay.
  int writer_nice = 10;
  // Test hook: the writer thread sleeps this long per message, so a test
  // can force the queue to overflow.
  std::chrono::microseconds writer_delay{0};
  // Key/values of the run (scene text, versions, host...), written as the
  // "fahr_run" Metadata record at the start.
  std::map<std::string, std::string> run_metadata;
};

struct RecorderStats {
  std::uint64_t received = 0, written = 0, dropped = 0, skipped = 0;
  std::uint64_t bytes = 0;  // message bytes written (before compression)
  std::size_t queue_peak_bytes = 0;
};

class Recorder {
 public:
  Recorder(common::Participant& participant, RecorderOptions options);
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // Stops the subscriptions, writes what is queued, the loss and service
  // Metadata, and closes the file. Called by the destructor if not before.
  void stop();

  RecorderStats stats() const;
  std::vector<WriterTally> tallies() const { return accounting_.snapshot(); }
  std::vector<std::string> files() const;
  // Writers (subscriptions matched) over all topics, for a ready check.
  int matched_writers() const;
  // Writers matched on each topic, by name, in the order of the topics.
  std::vector<std::pair<std::string, int>> matched_by_topic() const;
  bool bytes_as_received() const;

  // One topic the recorder subscribes to.
  struct Topic {
    std::string name;       // "fahr/DevicePose"
    std::string type_name;  // "fahr::msg::DevicePose"
    bool keyed = false;
    std::string key_field;          // "device_id", "body_id", ...
    common::QosProfile writer_qos;  // what fahr's writers offer (topics.h role)
    common::QosProfile qos;         // the recorder's reader QoS
    std::string role;
    // Never dropped for a full queue: low-rate topics the books and a
    // replay depend on (reports, the scene, lockstep).
    bool always_queue = false;
    std::uint32_t decimate = 1;
    std::uint16_t schema_id = 0;
  };

 private:
  struct Item {
    std::size_t topic = 0;
    std::uint32_t key = 0;
    std::uint32_t writer_id = 0;
    std::uint64_t seq = 0;
    std::int64_t source_time_ns = 0;
    std::int64_t receive_time_ns = 0;
    std::vector<std::uint8_t> bytes;
  };
  struct ServiceInfo {
    std::string name, host, vendor;
    std::uint32_t pid = 0;
  };

  void on_sample(std::size_t topic, std::span<const std::uint8_t> cdr, std::int64_t source_ns);
  void run_writer();
  void write_item(Item& item);
  void note_status(Item& item);
  void write_closing_metadata();

  RecorderOptions options_;
  std::vector<Topic> topics_;
  LossAccounting accounting_;
  mcap::Writer writer_;
  std::map<std::pair<std::size_t, std::uint32_t>, std::uint16_t> channels_;
  std::map<std::uint32_t, ServiceInfo> services_;

  mutable std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  std::deque<Item> queue_;
  std::vector<std::vector<std::uint8_t>> spare_;  // buffers to reuse
  std::size_t queue_bytes_ = 0;
  bool stopping_ = false;
  RecorderStats stats_;

  std::thread thread_;
  std::vector<std::unique_ptr<common::RawSubscriber>> subscribers_;
  bool stopped_ = false;
};

}  // namespace fahr::logger_service
