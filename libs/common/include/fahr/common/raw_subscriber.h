// A reader of serialized samples, for recorders: every sample's bytes as
// XCDR1 with the 4-byte encapsulation header, exactly as they arrived on
// Fast DDS and Cyclone DDS (serialized again from the typed sample on the
// in-process bus, which carries no bytes). A participant carries a topic
// type either raw or typed, not both.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

#include "fahr/common/participant.h"
#include "fahr/common/topics.h"

namespace fahr::common {

class RawSubscriber final : private detail::RawSampleSink {
 public:
  // Called on the vendor thread for every sample; `cdr` is valid during the
  // call only. It must be quick: copy and hand over, never touch a disk.
  using Handler =
      std::function<void(std::span<const std::uint8_t> cdr, std::int64_t source_time_ns)>;

  RawSubscriber(Participant& participant, const detail::TypeSupport& type, std::string topic_name,
                const QosProfile& qos, Handler handler)
      : handler_(std::move(handler)) {
    detail::EndpointSpec spec{&type, std::move(topic_name), qos};
    reader_ = participant.backend().create_raw_reader(spec, this);
    as_received_ = participant.backend().raw_bytes_as_received();
  }
  template <class T>
  static std::unique_ptr<RawSubscriber> create(Participant& participant, const QosProfile& qos,
                                               Handler handler) {
    return std::make_unique<RawSubscriber>(participant, detail::type_support<T>(),
                                           std::string(TopicTraits<T>::kName), qos,
                                           std::move(handler));
  }
  ~RawSubscriber() override { reader_.reset(); }  // stop deliveries before members go
  RawSubscriber(const RawSubscriber&) = delete;
  RawSubscriber& operator=(const RawSubscriber&) = delete;

  int matched_writers() const { return reader_->matched_writers(); }
  // False if the bytes are serialized again rather than as received.
  bool bytes_as_received() const { return as_received_; }

 private:
  void deliver_raw(const std::uint8_t* data, std::size_t size,
                   std::int64_t source_time_ns) override {
    handler_(std::span<const std::uint8_t>(data, size), source_time_ns);
  }

  Handler handler_;
  bool as_received_ = false;
  std::unique_ptr<detail::ReaderBackend> reader_;
};

}  // namespace fahr::common
