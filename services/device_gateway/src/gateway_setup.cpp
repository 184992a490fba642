// The gateway's back-end from its options (see gateway_setup.h).
#include "fahr/gateway_service/gateway_setup.h"

#include <cstdio>
#include <string>
#include <utility>

#include "fahr/device/recording.h"
#include "fahr/device/replay_backend.h"
#include "fahr/device/simulated_backend.h"
#include "fahr/device/trajectory.h"
#ifdef FAHR_HAVE_OPENHAPTICS
#include "fahr/device/openhaptics_backend.h"
#endif

namespace fahr::gateway_service {

std::optional<GatewaySetup> make_setup(const GatewayOptions& o) {
  GatewaySetup s;
  if (!device::model_by_name(o.model, s.config.model)) {
    std::fprintf(stderr, "fahr_device_gateway: --model: unknown device '%s' (touch_x, touch)\n",
                 o.model.c_str());
    return std::nullopt;
  }
  s.duration_s = o.duration_s;
  if (o.backend == "simulated") {
    device::Script script = device::Script::kIntubation;
    device::script_by_name(o.script, script);
    const device::HandImpedance hand;
    auto trajectory =
        device::script_trajectory(script, s.config.model.peak_force_n, hand.stiffness_npm);
    if (s.duration_s == 0.0) s.duration_s = trajectory.duration().count();
    s.backend = std::make_unique<device::SimulatedBackend>(
        std::move(trajectory), hand, s.config.model, s.config.mapping, s.config.period);
  } else if (o.backend == "replay") {
    device::Recording recording;
    if (const std::string error = device::read_recording(o.replay_file, recording);
        !error.empty()) {
      std::fprintf(stderr, "fahr_device_gateway: --replay-file: %s\n", error.c_str());
      return std::nullopt;
    }
    if (s.duration_s == 0.0 && !recording.samples.empty()) {
      s.duration_s = 1e-9 * static_cast<double>(recording.samples.back().device_time_ns -
                                                recording.samples.front().device_time_ns) +
                     1e-3;
    }
    s.backend = std::make_unique<device::ReplayBackend>(std::move(recording));
  } else if (o.backend == "remote") {
    auto remote = std::make_unique<device::RemoteInputBackend>(s.config.model);
    s.remote = remote.get();
    s.backend = std::move(remote);
  } else {
#ifdef FAHR_HAVE_OPENHAPTICS
    std::fprintf(stderr,
                 "fahr_device_gateway: the OpenHaptics servo loop runs in the HD scheduler; "
                 "use --mode realtime (not wired to the HD scheduler in this build yet)\n");
#else
    std::fprintf(
        stderr,
        "fahr_device_gateway: built without OpenHaptics (HD/hd.h and libHD not found by CMake)\n");
#endif
    return std::nullopt;
  }
  return s;
}

}  // namespace fahr::gateway_service
