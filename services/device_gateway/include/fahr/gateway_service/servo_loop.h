// The gateway's servo loop over DDS: in real time (sleep_until, opt-in spin
// and SCHED_FIFO) or in lockstep (one tick per granted base step),
// publishing DevicePose every tick and handing the status figures to
// GatewayMetrics a few times a second; and the DevicePose recording kept
// for --record-file, written after the run.
#pragma once

#include <cstdint>
#include <vector>

#include "fahr/common/participant.h"
#include "fahr/common/service_reporter.h"
#include "fahr/device/servo_core.h"
#include "fahr/gateway_service/gateway_options.h"
#include "fahr/gateway_service/gateway_setup.h"
#include "fahr/gateway_service/status_reporter.h"

namespace fahr::gateway_service {

// What the servo thread keeps between ticks for the status and the recording.
struct LoopState {
  StatusSnapshot snapshot;
  std::vector<device::DevicePoseSample> recorded;
  bool recording = false;
  std::uint64_t seq_mismatches = 0;
  // Real time: times the loop was far behind and started again from now,
  // and the ticks it skipped so.
  std::uint64_t resyncs = 0;
  std::uint64_t skipped_ticks = 0;
};

// The recording's room (--record-file: the run's length, or at most an hour
// until SIGINT), reserved before the loop so the tick never allocates.
void prepare_recording(const GatewayOptions& o, const GatewaySetup& setup, LoopState& state);
// Writes the recorded poses to --record-file (if any); false after a
// message on stderr when the file cannot be written.
bool write_recording(const GatewayOptions& o, const LoopState& state);

// Each returns the program's exit status.
int run_realtime(const GatewayOptions& o, GatewaySetup& setup, common::Participant& participant,
                 GatewayMetrics& metrics, common::TickRecorder& recorder, LoopState& state);
int run_lockstep(const GatewayOptions& o, GatewaySetup& setup, common::Participant& participant,
                 GatewayMetrics& metrics, common::TickRecorder& recorder, LoopState& state);

}  // namespace fahr::gateway_service
