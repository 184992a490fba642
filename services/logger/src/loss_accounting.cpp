// Sequence gaps, recorder drops and sent counts per writer.
#include "fahr/logger_service/loss_accounting.h"

namespace fahr::logger_service {

WriterTally& LossAccounting::tally(const std::string& topic, std::uint32_t writer_id) {
  auto [it, fresh] = writers_.try_emplace({topic, writer_id});
  if (fresh) {
    it->second.topic = topic;
    it->second.writer_id = writer_id;
  }
  return it->second;
}

std::uint64_t LossAccounting::on_receive(const std::string& topic, std::uint32_t writer_id,
                                         std::uint64_t seq) {
  std::lock_guard lock(mutex_);
  WriterTally& t = tally(topic, writer_id);
  if (t.received++ == 0) t.first_seq = seq;
  if (seq > t.highest_seq) {
    // From 1: the samples sent before the recorder matched count as gaps.
    const std::uint64_t gap = seq - t.highest_seq - 1;
    t.gaps += gap;
    t.highest_seq = seq;
    return gap;
  }
  // An older sample after a newer one: it fills a gap counted before.
  ++t.late;
  if (t.gaps > 0) --t.gaps;
  return 0;
}

void LossAccounting::on_drop(const std::string& topic, std::uint32_t writer_id) {
  std::lock_guard lock(mutex_);
  ++tally(topic, writer_id).drops;
}

void LossAccounting::on_skipped(const std::string& topic, std::uint32_t writer_id) {
  std::lock_guard lock(mutex_);
  ++tally(topic, writer_id).skipped;
}

void LossAccounting::on_recorded(const std::string& topic, std::uint32_t writer_id) {
  std::lock_guard lock(mutex_);
  ++tally(topic, writer_id).recorded;
}

void LossAccounting::on_reported_sent(const std::string& topic, std::uint32_t writer_id,
                                      std::uint64_t sent) {
  std::lock_guard lock(mutex_);
  auto& t = tally(topic, writer_id);
  t.reported_sent = std::max(t.reported_sent, sent);
}

std::vector<WriterTally> LossAccounting::snapshot() const {
  std::lock_guard lock(mutex_);
  std::vector<WriterTally> out;
  out.reserve(writers_.size());
  for (const auto& [key, t] : writers_) out.push_back(t);
  return out;
}

std::uint64_t LossAccounting::total_drops() const {
  std::lock_guard lock(mutex_);
  std::uint64_t n = 0;
  for (const auto& [key, t] : writers_) n += t.drops;
  return n;
}

}  // namespace fahr::logger_service
