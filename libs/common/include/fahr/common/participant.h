// A participant on the fahr bus: one per service process (or one per
// service in an in-process run). Owns the vendor backend and the events.
#pragma once

#include <cstdint>
#include <memory>

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

 private:
  TransportConfig config_;
  std::uint32_t writer_id_;
  std::unique_ptr<EventLog> events_;
  std::unique_ptr<detail::ParticipantBackend> backend_;
};

}  // namespace fahr::common
