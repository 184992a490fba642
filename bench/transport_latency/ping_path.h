// One way of sending a ping and seeing its echo: through the fahr
// transport, or through a vendor's raw API. The benchmark times them side
// by side in one run.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "fahr/common/vendor.h"

namespace fahr::bench {

// What is sent: a DevicePose (about 200 bytes) or a DeformationState whose
// positions and velocities fill `payload_bytes`.
struct Payload {
  std::string name;
  bool small = true;
  std::size_t payload_bytes = 0;
};

inline constexpr const char* kTransportPing = "fahr/bench/ping";
inline constexpr const char* kTransportPong = "fahr/bench/pong";
inline constexpr const char* kRawPing = "fahr/bench/raw_ping";
inline constexpr const char* kRawPong = "fahr/bench/raw_pong";

class PingPath {
 public:
  virtual ~PingPath() = default;
  // Sends ping `id` (carried in servo_tick / step).
  virtual void ping(std::uint64_t id) = 0;
  // Waits until echo `id` has come back.
  virtual bool wait_echo(std::uint64_t id, std::chrono::milliseconds timeout) = 0;
};

// Echoes every ping back. Lives until destroyed.
class EchoPath {
 public:
  virtual ~EchoPath() = default;
};

// `security`: a station's DDS Security folder (deployment/security/), or
// empty for none; the identity is fahr_transport_latency.
std::unique_ptr<PingPath> make_transport_ping(common::Vendor vendor, std::uint32_t domain,
                                              const Payload& payload,
                                              const std::string& security = {});
std::unique_ptr<EchoPath> make_transport_echo(common::Vendor vendor, std::uint32_t domain,
                                              const Payload& payload,
                                              const std::string& security = {});
std::unique_ptr<PingPath> make_raw_fast_ping(std::uint32_t domain, const Payload& payload);
std::unique_ptr<EchoPath> make_raw_fast_echo(std::uint32_t domain, const Payload& payload);
std::unique_ptr<PingPath> make_raw_cyclone_ping(std::uint32_t domain, const Payload& payload);
std::unique_ptr<EchoPath> make_raw_cyclone_echo(std::uint32_t domain, const Payload& payload);

}  // namespace fahr::bench
