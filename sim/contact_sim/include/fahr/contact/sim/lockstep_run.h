// One process, lockstep in simulated time: the haptic loop at 1 kHz and the
// FEM every `fem_period_ticks` ticks, with the read rule of
// fahr::common::producer_step_for: haptic tick k reads the FEM output of the
// FEM's newest step strictly before k, and the FEM step at k reads the
// ContactSet (or penalty forces) of haptic tick k - 1.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <vector>

#include "fahr/contact/contact_response.h"
#include "fahr/contact/penalty_response.h"
#include "fahr/contact/sim/fem_driver.h"
#include "fahr/contact/sim/tool_shapes.h"
#include "fahr/fem/contact_set.h"

namespace fahr::contact::sim {

enum class Method : std::uint8_t { kForceAware, kNaive, kPenalty };

struct LockstepConfig {
  Method method = Method::kForceAware;
  int fem_period_ticks = 20;  // 1 kHz / FEM rate, >= 1
  double dt_s = 0.001;        // haptic tick, s
  ResponseSettings response;
  PenaltySettings penalty;
  ToolShape tool;
  std::vector<PlaneObstacle> obstacles;
  double renderable_force_n = 3.0;    // N
  double max_stiffness_npm = 1480.0;  // N/m
};

struct TickRecord {
  std::uint64_t tick = 0;
  double time_s = 0.0;
  Eigen::Vector3d device_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d proxy_m = Eigen::Vector3d::Zero();
  // The ForceCommand's force on the stylus (force-aware and naive: at most
  // the renderable force; penalty: unsaturated, as the baseline asks).
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  double tissue_reaction_n = 0.0;
  bool lost_track = false;
  Eigen::Vector3d gap_m = Eigen::Vector3d::Zero();
  std::uint32_t active = 0;
  bool fem_stepped = false;  // the FEM stepped at this tick (after the haptic tick)
  FemStepReport fem;         // valid when fem_stepped
  // Largest penetration of an active tool constraint after the FEM's
  // projection of this step, m (valid when fem_stepped).
  double active_penetration_m = 0.0;
  // Largest penetration of a tool contact sent as force only (a held load,
  // or a wedge's clamped forces), which the FEM does not project, m (valid
  // when fem_stepped): the tissue may flow into a tool held still past the
  // limit, since holding it out would take more force than the device has.
  double force_only_penetration_m = 0.0;
  TickReport response;
  // Deepest row penetration at the tool pose the FEM will see (penalty:
  // the device pose; rows of this tick), m.
  double max_row_penetration_m = 0.0;
  // Wall time of the response's tick() (collision rows excluded), s.
  double tick_time_s = 0.0;
  bool finite = true;
};

class LockstepRun {
 public:
  LockstepRun(const LockstepConfig& config, FemDriver& fem, const Eigen::Vector3d& device_start_m);

  // Runs `ticks` ticks; device(tick) gives the device position. `observe`
  // (optional) sees each tick's record.
  void run(std::uint64_t ticks, const std::function<Eigen::Vector3d(std::uint64_t)>& device,
           const std::function<void(const TickRecord&)>& observe);

  ContactResponse& response() { return response_; }

 private:
  void haptic_tick(const Eigen::Vector3d& device_m, TickRecord& record);
  void fem_step(TickRecord& record);

  LockstepConfig config_;
  FemDriver& fem_;
  ContactResponse response_;
  PenaltyResponse penalty_;
  std::vector<ContactRow> rows_;
  fem::ContactSet pending_;  // output of the last haptic tick
  fem::ContactSet applied_;  // what the FEM step reads
  std::vector<double> pending_forces_, applied_forces_;
  std::uint64_t tick_ = 0;
  Eigen::Vector3d previous_device_m_;
};

// Amplitude (N, peak) of the f Hz line of x sampled every dt after removing
// its least-squares line, by a direct DFT over whole periods of f.
double line_amplitude(std::span<const double> x, double dt_s, double frequency_hz);

}  // namespace fahr::contact::sim
