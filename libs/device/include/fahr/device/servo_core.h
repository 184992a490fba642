// One servo tick of the gateway, independent of clock and transport: read
// the device, screen the newest ForceCommand, render F_k - K_k (x_now - x_k),
// keep it passive, apply the safety limits and the thermal derating, command
// the device and fill the DevicePose to publish. The service main calls it
// from its real-time loop or its lockstep loop; tests call it directly in
// simulated time. tick() allocates nothing, blocks on nothing, logs nothing.
#pragma once

#include <chrono>
#include <cstdint>

#include "fahr/device/backend.h"
#include "fahr/device/device_model.h"
#include "fahr/device/force_renderer.h"
#include "fahr/device/latency_histogram.h"
#include "fahr/device/passivity_controller.h"
#include "fahr/device/safety_gate.h"
#include "fahr/device/thermal_model.h"
#include "fahr/device/workspace_mapping.h"

namespace fahr::device {

struct GatewayConfig {
  DeviceModel model;
  SafetyConfig safety;
  RenderConfig render;
  PassivityConfig passivity;
  WorkspaceMapping mapping;
  // Servo period, > 0: 1 ms, the clock of the haptic domain.
  std::chrono::nanoseconds period{std::chrono::milliseconds(1)};
};

class ServoCore {
 public:
  // `backend` must outlive the core. Throws std::invalid_argument naming the
  // field if the configuration is invalid (setup time, not in the tick).
  ServoCore(const GatewayConfig& config, Backend& backend);

  // One tick at gateway time `now` (monotonic in real time, simulated in
  // lockstep). `incoming`: the newest ForceCommand if one arrived since the
  // last tick, else null. Returns the DevicePose of this tick; its seq is
  // servo_tick + 1, which the transport must stamp (one write per tick).
  const DevicePoseSample& tick(std::chrono::nanoseconds now, const ForceCommandSample* incoming);

  std::uint64_t ticks() const { return tick_; }
  const SafetyCounters& safety_counters() const { return safety_.counters(); }
  const PassivityController& passivity() const { return passivity_; }
  const ThermalModel& thermal() const { return thermal_; }
  // Motion-to-force latency of each accepted command: from the tick its
  // answered pose was read to the tick it first shaped the force.
  LatencyHistogram& latency() { return latency_; }
  const LatencyHistogram& latency() const { return latency_; }
  // The same over the whole run (never reset): what a trainee felt.
  const LatencyHistogram& run_latency() const { return run_latency_; }
  // Energy the device has delivered to the hand, J (sum of F . v dt; world frame).
  double energy_to_hand_j() const { return energy_to_hand_j_; }
  // Largest rendered force magnitude so far, N.
  double peak_rendered_force_n() const { return peak_rendered_n_; }
  const GatewayConfig& config() const { return config_; }

 private:
  GatewayConfig config_;
  Backend& backend_;
  std::chrono::duration<double> dt_;
  ThermalModel thermal_;
  ForceRenderer renderer_;
  PassivityController passivity_;
  SafetyGate safety_;
  LatencyHistogram latency_;
  LatencyHistogram run_latency_;
  PoseTimeRing pose_times_;
  DevicePoseSample pose_;
  std::uint64_t tick_ = 0;
  std::chrono::nanoseconds last_now_{-1};  // the previous tick's time (-1: none yet)
  bool transition_ = false;                // the command in use ramps or slews (ForceCommandSample)
  double energy_to_hand_j_ = 0.0;
  double peak_rendered_n_ = 0.0;
};

}  // namespace fahr::device
