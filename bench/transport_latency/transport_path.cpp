// Ping and echo through fahr's Publisher/Subscriber.
#include <optional>

#include "echo_waiter.h"
#include "fahr/common/publisher.h"
#include "fahr/common/subscriber.h"
#include "ping_path.h"

namespace fahr::bench {
namespace {

common::QosProfile bench_qos() {
  common::QosProfile qos;
  qos.reliability = common::Reliability::kReliable;
  qos.history_depth = 1;
  return qos;
}

common::TransportConfig config_for(common::Vendor vendor, std::uint32_t domain,
                                   const std::string& security) {
  common::TransportConfig config;
  config.vendor = vendor;
  config.domain_id = domain;
  config.participant_name = "fahr_transport_latency";
  config.security_dir = security;
  return config;
}

std::uint64_t id_of(const msg::DevicePose& s) {
  return s.servo_tick();
}
std::uint64_t id_of(const msg::DeformationState& s) {
  return s.step();
}
void set_id(msg::DevicePose& s, std::uint64_t id) {
  s.servo_tick(id);
}
void set_id(msg::DeformationState& s, std::uint64_t id) {
  s.step(id);
}
void size(msg::DevicePose&, std::size_t) {}
void size(msg::DeformationState& s, std::size_t bytes) {
  s.positions_m().assign(bytes / 8, 0.5F);
  s.velocities_mps().assign(bytes / 8, -0.5F);
}

template <class T>
class TransportPing final : public PingPath {
 public:
  TransportPing(common::Vendor vendor, std::uint32_t domain, const Payload& payload,
                const std::string& security)
      : participant_(config_for(vendor, domain, security)),
        pub_(participant_, bench_qos(), kTransportPing),
        sub_(participant_, bench_qos(), kTransportPong,
             [this](const T& sample, const common::SampleInfo&) {
               waiter_.arrived(id_of(sample));
             }) {
    size(sample_, payload.payload_bytes);
  }
  void ping(std::uint64_t id) override {
    set_id(sample_, id);
    pub_.write(sample_);
  }
  bool wait_echo(std::uint64_t id, std::chrono::milliseconds timeout) override {
    return waiter_.wait(id, timeout);
  }

 private:
  EchoWaiter waiter_;
  T sample_;
  common::Participant participant_;
  common::Publisher<T> pub_;
  common::Subscriber<T> sub_;
};

template <class T>
class TransportEcho final : public EchoPath {
 public:
  TransportEcho(common::Vendor vendor, std::uint32_t domain, const std::string& security)
      : participant_(config_for(vendor, domain, security)),
        pub_(participant_, bench_qos(), kTransportPong),
        sub_(participant_, bench_qos(), kTransportPing,
             [this](const T& sample, const common::SampleInfo&) {
               echo_ = sample;  // reuses capacity after the first
               pub_.write(echo_);
             }) {}

 private:
  T echo_;
  common::Participant participant_;
  common::Publisher<T> pub_;
  common::Subscriber<T> sub_;
};

}  // namespace

std::unique_ptr<PingPath> make_transport_ping(common::Vendor vendor, std::uint32_t domain,
                                              const Payload& payload, const std::string& security) {
  if (payload.small)
    return std::make_unique<TransportPing<msg::DevicePose>>(vendor, domain, payload, security);
  return std::make_unique<TransportPing<msg::DeformationState>>(vendor, domain, payload, security);
}

std::unique_ptr<EchoPath> make_transport_echo(common::Vendor vendor, std::uint32_t domain,
                                              const Payload& payload, const std::string& security) {
  if (payload.small)
    return std::make_unique<TransportEcho<msg::DevicePose>>(vendor, domain, security);
  return std::make_unique<TransportEcho<msg::DeformationState>>(vendor, domain, security);
}

}  // namespace fahr::bench
