// Per writer (topic and writer_id) accounting of what a recorder got: a
// sequence gap is a lost sample, a sample the recorder could not queue is
// its own drop, and the writer's sent count (its last sequence number, or
// what it reports in ServiceStatus, whichever is higher) closes the books:
//   recorded + gaps + drops (+ skipped, under decimation) = sent,
// exactly, for every writer.
// A restarted service is a new writer (a new writer_id).
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

namespace fahr::logger_service {

struct WriterTally {
  std::string topic;
  std::uint32_t writer_id = 0;
  std::uint64_t first_seq = 0;  // the first sample that reached the recorder
  std::uint64_t highest_seq = 0;
  std::uint64_t received = 0;       // samples that reached the recorder
  std::uint64_t gaps = 0;           // sequence numbers never seen (so far)
  std::uint64_t drops = 0;          // received, but the queue was full
  std::uint64_t recorded = 0;       // written to the file
  std::uint64_t skipped = 0;        // left out on purpose (decimation)
  std::uint64_t late = 0;           // arrived after a later one (filled a gap)
  std::uint64_t reported_sent = 0;  // from the writer's ServiceStatus

  std::uint64_t sent() const { return std::max(highest_seq, reported_sent); }
  // Gaps including the samples after the last one seen that the writer
  // says it sent.
  std::uint64_t total_gaps() const { return gaps + (sent() - highest_seq); }
  // Of those, the samples sent before the recorder matched the writer.
  std::uint64_t leading_gaps() const { return first_seq > 0 ? first_seq - 1 : sent(); }
};

class LossAccounting {
 public:
  // A sample arrived (subscriber thread). Returns the gap it revealed.
  std::uint64_t on_receive(const std::string& topic, std::uint32_t writer_id, std::uint64_t seq);
  void on_drop(const std::string& topic, std::uint32_t writer_id);
  void on_skipped(const std::string& topic, std::uint32_t writer_id);
  void on_recorded(const std::string& topic, std::uint32_t writer_id);
  // The writer's own count from its ServiceStatus ("sent <topic>").
  void on_reported_sent(const std::string& topic, std::uint32_t writer_id, std::uint64_t sent);

  std::vector<WriterTally> snapshot() const;
  std::uint64_t total_drops() const;

 private:
  WriterTally& tally(const std::string& topic, std::uint32_t writer_id);
  mutable std::mutex mutex_;
  std::map<std::pair<std::string, std::uint32_t>, WriterTally> writers_;
};

}  // namespace fahr::logger_service
