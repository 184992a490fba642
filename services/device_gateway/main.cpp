// fahr_device_gateway: the 1 kHz servo loop of the haptic domain. Thin: it
// builds the back-end and fahr::device::ServoCore from the flags
// (gateway_setup.h), then runs the core in real time or in lockstep
// (servo_loop.h), publishing DevicePose every tick and ServiceStatus a few
// times a second.
#include <chrono>
#include <cstdio>
#include <exception>
#include <string>

#include "fahr/common/participant.h"
#include "fahr/common/service_reporter.h"
#include "fahr/common/stop_signal.h"
#include "fahr/gateway_service/gateway_options.h"
#include "fahr/gateway_service/gateway_setup.h"
#include "fahr/gateway_service/servo_loop.h"
#include "fahr/gateway_service/status_reporter.h"

namespace fahr::gateway_service {
namespace {

int run(int argc, char** argv) {
  // Options and set-up.
  const auto options = parse_options(argc, argv);
  if (!options) return 2;
  auto setup = make_setup(*options);
  if (!setup) return 2;
  common::install_stop_handlers();
  common::Participant participant(common::transport_config_from(
      options->dds, options->domain, options->profile, "device_gateway", options->security));
  common::TickRecorder recorder;
  GatewayMetrics metrics;
  common::ServiceReporter reporter(
      participant,
      {"device_gateway", 1000.0,
       std::chrono::milliseconds(static_cast<long>(1000.0 / options->status_hz))},
      recorder, [&metrics](auto& figures) { metrics.fill(figures); });
  LoopState state;
  prepare_recording(*options, *setup, state);
  std::fprintf(stderr, "fahr_device_gateway: %s, backend %s, model %s, %s, %.1f s\n",
               std::string(common::vendor_name(participant.vendor())).c_str(),
               options->backend.c_str(), setup->config.model.name.c_str(), options->mode.c_str(),
               setup->duration_s);

  // The loop.
  reporter.set_state(msg::SERVICE_RUNNING);
  const int code = options->mode == "lockstep"
                       ? run_lockstep(*options, *setup, participant, metrics, recorder, state)
                       : run_realtime(*options, *setup, participant, metrics, recorder, state);

  // Shutdown: the last status, the run's figures, the recording.
  reporter.set_state(msg::SERVICE_STOPPING);
  reporter.report();
  std::printf("device_gateway: %s\n", metrics.summary(reporter.late_periods()).c_str());
  if (state.seq_mismatches > 0) {
    std::fprintf(stderr,
                 "fahr_device_gateway: %llu DevicePose seq mismatches (pose seq != writer seq)\n",
                 static_cast<unsigned long long>(state.seq_mismatches));
  }
  if (!write_recording(*options, state)) return 1;
  return code;
}

}  // namespace
}  // namespace fahr::gateway_service

int main(int argc, char** argv) {
  try {
    return fahr::gateway_service::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_device_gateway: %s\n", e.what());
    return 1;
  }
}
