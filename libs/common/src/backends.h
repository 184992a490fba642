// Factories of the three backends; only participant.cpp calls them.
#pragma once

#include <memory>

#include "fahr/common/backend.h"
#include "fahr/common/transport_config.h"
#include "fahr/common/transport_event.h"

namespace fahr::common::detail {

std::unique_ptr<ParticipantBackend> make_fast_backend(const TransportConfig& config,
                                                      EventLog& events);
std::unique_ptr<ParticipantBackend> make_cyclone_backend(const TransportConfig& config,
                                                         EventLog& events);
std::unique_ptr<ParticipantBackend> make_inprocess_backend(const TransportConfig& config,
                                                           EventLog& events);

// Copies a topic name into an event, truncating it.
void set_event_topic(TransportEvent& event, std::string_view topic);

}  // namespace fahr::common::detail
