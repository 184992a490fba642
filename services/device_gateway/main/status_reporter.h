// ServiceStatus for the gateway, published from its own thread so the servo
// thread only copies a snapshot (a triple buffer, no allocation) a few times
// a second. Percentiles are over one report window: the servo thread resets
// its histograms after each snapshot.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>

#include "fahr/common/latest_sample.h"
#include "fahr/common/participant.h"
#include "fahr/common/publisher.h"
#include "fahr/device/latency_histogram.h"
#include "fahr/device/safety_gate.h"

namespace fahr::device_main {

struct StatusSnapshot {
  std::uint64_t ticks = 0;
  double window_s = 0.0;               // wall time the window covers, s
  std::uint64_t window_ticks = 0;
  std::uint64_t late_periods = 0;      // periods > 1.5x nominal since start
  device::SafetyCounters safety;
  device::SafetyState safety_state = device::SafetyState::kForceDisabled;
  double renderable_force_n = 0.0;
  double peak_force_n = 0.0;
  double heat = 0.0;
  double energy_to_hand_j = 0.0;
  double passivity_dissipated_j = 0.0;
  std::uint64_t passivity_active_ticks = 0;
  std::uint64_t remote_rejected = 0;
  device::LatencyHistogram motion_to_force;
  device::LatencyHistogram period{std::chrono::microseconds(10)};
  device::LatencyHistogram tick_cpu{std::chrono::microseconds(1)};
};

class StatusReporter {
 public:
  StatusReporter(common::Participant& participant, double rate_hz, double nominal_rate_hz, std::string backend);
  ~StatusReporter();
  StatusReporter(const StatusReporter&) = delete;
  StatusReporter& operator=(const StatusReporter&) = delete;

  // Servo thread: hands over a snapshot (copy into a preallocated slot).
  void offer(const StatusSnapshot& snapshot) { latest_.publish(snapshot, {}); }
  // Publishes the newest snapshot now (also used once at the end).
  void publish_now();
  // A one-line summary of the last snapshot, for the end of a run.
  std::string summary() const;

 private:
  void run();

  common::Participant& participant_;
  double period_s_;
  double nominal_rate_hz_;
  std::string backend_;
  common::LatestSample<StatusSnapshot> latest_;
  StatusSnapshot last_;
  common::Publisher<msg::ServiceStatus> publisher_;
  msg::ServiceStatus status_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace fahr::device_main
