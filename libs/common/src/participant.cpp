// Participant: validation, identity and the choice of backend.
#include "fahr/common/participant.h"

#include <random>

#include "backends.h"

namespace fahr::common {

namespace detail {
void set_event_topic(TransportEvent& event, std::string_view topic) {
  const std::size_t n = std::min(topic.size(), event.topic.size() - 1);
  std::copy_n(topic.data(), n, event.topic.data());
  event.topic[n] = '\0';
}
}  // namespace detail

namespace {
std::uint32_t random_writer_id() {
  std::random_device device;
  std::uint32_t id = 0;
  while (id == 0) id = device();  // 0 means "no writer" in SampleInfo
  return id;
}
}  // namespace

Participant::Participant(const TransportConfig& config)
    : config_(config), writer_id_(random_writer_id()), events_(std::make_unique<EventLog>()) {
  validate(config_);
  switch (config_.vendor) {
    case Vendor::kFastDds:
      backend_ = detail::make_fast_backend(config_, *events_);
      break;
    case Vendor::kCyclone:
      backend_ = detail::make_cyclone_backend(config_, *events_);
      break;
    case Vendor::kInProcess:
      backend_ = detail::make_inprocess_backend(config_, *events_);
      break;
  }
}

Participant::~Participant() = default;

std::atomic<std::uint64_t>& Participant::sent_counter(std::string_view topic) {
  std::lock_guard lock(sent_mutex_);
  for (auto& [name, count] : sent_) {
    if (name == topic) return count;
  }
  auto& entry = sent_.emplace_back(std::piecewise_construct, std::forward_as_tuple(topic),
                                   std::forward_as_tuple(0));
  return entry.second;
}

void Participant::for_each_sent(
    const std::function<void(std::string_view topic, std::uint64_t sent)>& fn) {
  std::lock_guard lock(sent_mutex_);
  for (const auto& [name, count] : sent_) fn(name, count.load(std::memory_order_relaxed));
}

}  // namespace fahr::common

#if defined(FAHR_SANITIZE_BUILD)
// Fast DDS 2.9.1 (Debian) deletes an RTPSReader through a base of another
// size in its liveliness protocol's destructor (WLP::~WLP ->
// RTPSReader::~RTPSReader): AddressSanitizer's new-delete-type-mismatch
// fires inside the vendor at every participant deletion. The check stays on
// for everything else.
extern "C" const char* __asan_default_options() {
  return "new_delete_type_mismatch=0";
}
#endif
