// A typed writer. write() stamps the SampleHeader (sequence number, source
// time, writer id) and hands the sample to the vendor; it allocates nothing
// itself, so a 1 kHz loop may call it.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "fahr/common/clock.h"
#include "fahr/common/participant.h"
#include "fahr/common/topics.h"

namespace fahr::common {

template <class T>
class Publisher {
 public:
  explicit Publisher(Participant& participant,
                     QosProfile qos = QosProfile::for_role(TopicTraits<T>::kRole),
                     std::string_view topic_name = TopicTraits<T>::kName)
      : writer_id_(participant.writer_id()), sent_(&participant.sent_counter(topic_name)) {
    detail::EndpointSpec spec{&detail::type_support<T>(), std::string(topic_name), qos};
    writer_ = participant.backend().create_writer(spec);
  }

  // Stamps header().seq, source_time_ns and writer_id; the caller sets
  // sim_time_ns and sim_step. Returns false if the vendor refused.
  bool write(T& sample) {
    auto& header = sample.header();
    // One sequence per topic and participant, whichever of its publishers
    // writes (one per body of a keyed topic): a recorder counts a writer's
    // losses by its gaps.
    seq_ = sent_->fetch_add(1, std::memory_order_relaxed) + 1;
    header.seq(seq_);
    header.writer_id(writer_id_);
    const std::int64_t now_ns = wall_now_ns();
    header.source_time_ns(now_ns);
    return writer_->write(&sample, now_ns);
  }

  void assert_liveliness() { writer_->assert_liveliness(); }
  // Reliable topics: waits until every matched reader has every sample
  // (before a shutdown, so the last reports reach a recorder); true if so.
  bool wait_for_acks(std::chrono::nanoseconds timeout) { return writer_->wait_for_acks(timeout); }
  int matched_readers() const { return writer_->matched_readers(); }
  std::uint64_t last_seq() const { return seq_; }

 private:
  std::uint32_t writer_id_;
  std::uint64_t seq_ = 0;
  std::atomic<std::uint64_t>* sent_;
  std::unique_ptr<detail::WriterBackend> writer_;
};

}  // namespace fahr::common
