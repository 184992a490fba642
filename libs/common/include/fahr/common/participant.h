// A participant on the fahr bus: one per service process (or one per
// service in an in-process run). Owns the vendor backend and the events.
#pragma once

#include <atomic>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <utility>

#include "fahr/common/backend.h"
#include "fahr/common/transport_config.h"
#include "fahr/common/transport_event.h"

namespace fahr::common {

class Participant {
 public:
  // Validates the configuration and joins the domain. Throws ConfigError
  // (bad configuration) or std::runtime_error (the vendor refused).
  explicit Participant(const TransportConfig& config);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  Vendor vendor() const { return config_.vendor; }
  const TransportConfig& config() const { return config_; }
  // Random identity of this participant, stamped into every SampleHeader.
  std::uint32_t writer_id() const { return writer_id_; }
  EventLog& events() { return *events_; }
  detail::ParticipantBackend& backend() { return *backend_; }

  // Samples this participant's writers of `topic` have sent, which is the
  // topic's last sequence number: every Publisher of the topic draws its
  // numbers from it (several write a keyed topic, one per instance). The status reporter publishes
  // each as the metric "sent <topic>", so a recorder can check that
  // recorded + lost = sent for every writer. The reference stays valid for
  // the participant's life, after the publisher is gone.
  std::atomic<std::uint64_t>& sent_counter(std::string_view topic);
  void for_each_sent(const std::function<void(std::string_view topic, std::uint64_t sent)>& fn);

 private:
  TransportConfig config_;
  std::uint32_t writer_id_;
  std::unique_ptr<EventLog> events_;
  std::unique_ptr<detail::ParticipantBackend> backend_;
  std::mutex sent_mutex_;
  std::deque<std::pair<std::string, std::atomic<std::uint64_t>>> sent_;
};

}  // namespace fahr::common
