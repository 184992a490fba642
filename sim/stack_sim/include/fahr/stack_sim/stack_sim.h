// The three services' own step code in one process, in lockstep: the
// gateway's servo tick (a simulated hand following a script), the haptic
// service's tissue digest and tick, the FEM service's step; no transport.
// Each base step k (1 ms) follows the read rule of the distributed lockstep
// (libs/common/include/fahr/common/lockstep.h): every service reads
// what the others produced before step k, so a run here is the run
// `deployment/run_local.sh --mode lockstep` makes over DDS, minus the wire,
// and the same on every machine. Tests and benchmarks that need the whole
// loop (the tongue overshoot of Figure 7, the penalty baseline beside it)
// run it here, tens of times faster than over DDS.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "contact_set.h"
#include "deformation_state.h"
#include "device_pose.h"
#include "fahr/common/lockstep.h"
#include "fahr/contact/force_aware.h"
#include "fahr/device/servo_core.h"
#include "fahr/device/simulated_backend.h"
#include "fahr/device/trajectory.h"
#include "fahr/fem_service/anatomy_fields.h"
#include "fahr/fem_service/fem_body_setup.h"
#include "fahr/fem_service/service_step.h"
#include "fahr/haptic_service/haptic_loop.h"
#include "fahr/haptic_service/haptic_setup.h"
#include "fahr/haptic_service/tissue_snapshot.h"
#include "fahr/metrics/duration_histogram.h"
#include "fahr/scene/scene.h"
#include "force_command.h"

namespace fahr::stack_sim {

// Choices the shipped services do not offer, kept so that a benchmark can
// rerun a comparison (docs/design/retired-modes.md): only bench code sets
// them; no scene key or service flag reaches them. The defaults are the
// services' own behaviour.
struct Experiments {
  // The FEM without its own anatomy pass: the haptic side finds the
  // tongue's obstacle contacts and the FEM projects them, as before the FEM
  // kept its nodes out of bone (haptic_service::set_up's fem_keeps_anatomy).
  bool haptic_side_anatomy = false;
  // Overrides the FEM's anatomy support springs (obstacle_support.h), their
  // stiffness over the node's diagonal of A; 0 turns them off.
  std::optional<double> fem_support_ratio;
  // Overrides the FEM's tool/anatomy alternation rounds per step
  // (ObstacleProjectionSettings::max_rounds) when > 0.
  int fem_anatomy_rounds = 0;
  // The held proxy backs off to keep the tissue at the limit
  // (contact::HeldProxy::kBackOff) instead of the scene's hold.
  bool back_off_held_proxy = false;
  // Overrides HapticSetup::candidate_margin_m when set, m.
  std::optional<double> candidate_margin_m;
};

struct StackOptions {
  device::Script script = device::Script::kIntubation;
  // The hand's keyframes instead of the script's (benches that try a motion).
  std::optional<device::Trajectory> keyframes;
  // Overshoot script: how far past the device's peak force the hand pulls.
  double overshoot_factor = 3.0;
  haptic_service::CollisionMethod collision = haptic_service::CollisionMethod::kAist;
  std::uint32_t device_id = 0;  // the gateway's default --device-id
  Experiments experiments;
};

class StackSim {
 public:
  // Builds the three services from the scene (seconds: the sphere filling,
  // the fields, the factorisation). Throws std::runtime_error naming what
  // the scene lacks (a device, a tool, one deformable body).
  StackSim(std::shared_ptr<const scene::Scene> scene, const StackOptions& options);
  StackSim(const StackSim&) = delete;
  StackSim& operator=(const StackSim&) = delete;

  // One base step: gateway, haptic and (at its period) FEM.
  void step();

  std::uint64_t steps() const { return step_; }
  double time_s() const { return 1e-9 * static_cast<double>(step_ * base_period_ns_); }
  std::uint64_t fem_period_steps() const { return fem_period_; }

  // The outputs of the last step (the FEM's: of its last step). With
  // several deformable bodies, body b's ContactSet (the scene's order;
  // contacts() is the first's).
  const msg::DevicePose& pose() const { return pose_; }
  const msg::ForceCommand& command() const { return command_; }
  const msg::ContactSet& contacts(std::size_t b = 0) const { return contacts_[b]; }
  bool fem_stepped() const { return fem_stepped_; }  // in the last step

  // The deformable bodies: the first (the tongue) by default.
  std::size_t body_count() const { return fems_.size(); }
  const fem::Body& body(std::size_t b = 0) const { return *fem_setups_[b]->body; }
  // Body b's largest node displacement from rest now, m.
  double largest_node_motion_m(std::size_t b = 0) const;
  fem::Body& body(std::size_t b = 0) { return *fem_setups_[b]->body; }  // energy() needs it
  const geometry::TetMesh& tongue_mesh() const { return fem_setups_.front()->mesh; }
  const fem_service::ServiceStep& fem(std::size_t b = 0) const { return *fems_[b]; }
  const device::ServoCore& gateway() const { return *gateway_; }
  const device::SimulatedBackend& hand() const { return *hand_; }
  const haptic_service::HapticLoop& haptic() const { return *haptic_; }
  const haptic_service::HapticSetup& haptic_setup() const { return haptic_setup_; }
  const scene::Scene& scene() const { return *scene_; }

  // Thread-CPU time of each haptic tick so far (the tick alone: no digest,
  // no transport), 5 us bins (up to 10 ms: the triangle baseline reaches ms).
  const metrics::DurationHistogram& haptic_tick_cpu() const { return haptic_tick_cpu_; }
  // Thread-CPU time of each FEM service step so far (the step and its
  // DeformationState, no transport), 50 us bins (up to 100 ms): against the FEM's period.
  // A FEM step's CPU on all the FEM's threads: its own and the background
  // factorisation's since the step before; and the step's thread alone.
  const metrics::DurationHistogram& fem_step_cpu() const { return fem_step_cpu_; }
  const metrics::DurationHistogram& fem_step_thread_cpu() const { return fem_step_thread_cpu_; }
  std::chrono::nanoseconds fem_background_cpu() const { return fem_background_cpu_; }
  std::chrono::nanoseconds last_fem_step_cpu() const { return last_fem_step_cpu_; }
  // Every FEM step's thread CPU and its parts (summed over the bodies), in
  // step order: which part the slow steps spend it in.
  struct FemStepCpu {
    std::int64_t thread_ns = 0;
    fem::StepParts parts;
  };
  const std::vector<FemStepCpu>& fem_step_parts() const { return fem_step_parts_; }

  // Output hashes as the distributed lockstep computes them.
  std::uint64_t gateway_hash() const { return gateway_hash_.value(); }
  std::uint64_t haptic_hash() const { return haptic_hash_.value(); }
  std::uint64_t fem_hash() const { return fem_hash_.value(); }

 private:
  std::shared_ptr<const scene::Scene> scene_;
  std::int64_t base_period_ns_;
  std::uint64_t fem_period_;

  device::GatewayConfig gateway_config_;
  std::unique_ptr<device::SimulatedBackend> hand_;
  std::unique_ptr<device::ServoCore> gateway_;

  haptic_service::HapticSetup haptic_setup_;
  std::unique_ptr<haptic_service::HapticLoop> haptic_;
  std::unique_ptr<haptic_service::TissueDigest> digest_;
  haptic_service::TissueSnapshot tissue_;

  // One FEM service stepping every deformable body, in the scene's order.
  std::vector<std::unique_ptr<fem_service::FemBodySetup>> fem_setups_;
  std::vector<std::unique_ptr<fem_service::ServiceStep>> fems_;
  std::vector<const msg::DeformationState*> fem_states_;

  // What each service published in the step before (the read rule); a
  // ContactSet per body. With several bodies the tick fills joined_, split
  // into next_contacts_ (haptic_service::split_contacts).
  msg::DevicePose pose_;
  msg::ForceCommand command_;
  std::vector<msg::ContactSet> contacts_;
  msg::DevicePose next_pose_;
  msg::ForceCommand next_command_;
  std::vector<msg::ContactSet> next_contacts_;
  msg::ContactSet joined_;
  std::vector<msg::ContactSet*> split_to_;
  device::ForceCommandSample command_sample_;
  bool fem_stepped_ = false;
  bool fem_published_ = false;
  std::uint64_t step_ = 0;

  metrics::DurationHistogram haptic_tick_cpu_{std::chrono::microseconds(5)};
  metrics::DurationHistogram fem_step_cpu_{std::chrono::microseconds(50)};
  metrics::DurationHistogram fem_step_thread_cpu_{std::chrono::microseconds(50)};
  std::chrono::nanoseconds fem_background_cpu_{0};
  std::chrono::nanoseconds last_fem_step_cpu_{0};
  std::vector<FemStepCpu> fem_step_parts_;
  common::OutputHash gateway_hash_;
  common::OutputHash haptic_hash_;
  common::OutputHash fem_hash_;
};

}  // namespace fahr::stack_sim
