// The gateway's figures for ServiceStatus. The servo thread hands a
// snapshot over (a copy into a preallocated triple-buffer slot, no
// allocation) a few times a second; common::ServiceReporter, on its own
// thread, turns the newest one into metrics beside the tick statistics and
// QoS events it publishes for every service. Latency percentiles are over
// one window: the servo thread resets its histogram after each snapshot.
#pragma once

#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "fahr/common/latest_sample.h"
#include "fahr/common/subscriber.h"
#include "fahr/device/latency_histogram.h"
#include "fahr/device/safety_gate.h"

namespace fahr::gateway_service {

struct StatusSnapshot {
  std::uint64_t ticks = 0;
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
  device::LatencyHistogram motion_to_force_run;  // since the gateway started
};

class GatewayMetrics {
 public:
  // Servo thread.
  void offer(const StatusSnapshot& snapshot) { latest_.publish(snapshot, {}); }
  // Reporter thread (a common::MetricsSource).
  void fill(std::vector<std::pair<std::string, double>>& metrics);
  // The last snapshot reported, in one line, for the end of a run.
  std::string summary(std::uint64_t late_periods);
  // Refusals of the ForceCommand reader: another writer than the haptic
  // service it follows (common::Admission).
  const std::shared_ptr<common::AdmissionCounts> command_admission =
      std::make_shared<common::AdmissionCounts>();

 private:
  common::LatestSample<StatusSnapshot> latest_;
  void take_newest();  // last_mutex_ held

  std::mutex last_mutex_;
  StatusSnapshot last_;
  // The newest window that had ForceCommands: a run's final snapshot often
  // covers only the few ticks after the last report, and must not hide it.
  device::LatencyHistogram last_latency_;
};

}  // namespace fahr::gateway_service
