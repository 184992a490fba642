// The gateway's device back-end and servo configuration, built from its
// options before the loop starts.
#pragma once

#include <memory>
#include <optional>

#include "fahr/device/backend.h"
#include "fahr/device/remote_input_backend.h"
#include "fahr/device/servo_core.h"
#include "fahr/gateway_service/gateway_options.h"

namespace fahr::gateway_service {

struct GatewaySetup {
  device::GatewayConfig config;
  std::unique_ptr<device::Backend> backend;
  device::RemoteInputBackend* remote = nullptr;  // non-null for --backend remote
  double duration_s = 0.0;                       // 0: until SIGINT
};

// Builds the back-end; nullopt (after a message on stderr) if it cannot be.
std::optional<GatewaySetup> make_setup(const GatewayOptions& o);

}  // namespace fahr::gateway_service
