// One haptic tick per DevicePose: sphere centres from the newest FEM state,
// the tool's contacts through the AIST, the contact response on the FEM's
// compliance, and the ForceCommand and ContactSet that answer it. Every
// buffer is sized in the constructor; take_state() and tick() allocate
// nothing once the wire samples hold their reserved capacity.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "contact_set.h"
#include "deformation_state.h"
#include "device_pose.h"
#include "fahr/contact/contact_response.h"
#include "fahr/haptic/contact_buffer.h"
#include "fahr/haptic/rigid_body.h"
#include "fahr/haptic/sphere_query.h"
#include "fahr/haptic/sphere_state.h"
#include "fahr/haptic/sphere_tree.h"
#include "force_command.h"
#include "haptic_setup.h"

namespace fahr::haptic_service {

// Figures the reporter thread reads while the loop runs (relaxed atomics:
// each is a single value, no invariant ties them together).
struct LoopMetrics {
  std::atomic<std::uint64_t> ticks{0};
  std::atomic<std::uint64_t> fem_states{0};
  std::atomic<std::uint64_t> bad_states{0};         // wrong size or non-finite positions: ignored
  std::atomic<std::uint32_t> tool_rows{0};          // rows of the last tick (touching and candidates)
  std::atomic<std::uint32_t> active_contacts{0};    // rows with lambda > 0, last tick
  std::atomic<std::uint32_t> obstacle_contacts{0};  // tongue vs anatomy, newest state
  std::atomic<std::uint64_t> rows_dropped{0};       // tool contacts beyond max_rows, total
  std::atomic<std::uint64_t> query_overflows{0};    // contact buffer full, total
  std::atomic<std::uint32_t> missing_compliance{0}; // rows on the fallback compliance, last tick
  std::atomic<std::uint64_t> lost_track_ticks{0};
  std::atomic<std::uint64_t> lost_track_episodes{0};
  std::atomic<bool> free_centres{false};            // the newest state carried free-motion centres
  std::atomic<double> reaction_n{0.0};              // last tissue reaction, N
  std::atomic<double> peak_force_n{0.0};            // largest |F_k| commanded, N
  // Work time of the two parts of a tick, largest since the last report
  // (the reporter resets them), us: a new FEM state (centres, refit,
  // tissue-obstacle contacts) and the tool query plus the solve.
  std::atomic<double> state_us_max{0.0};
  std::atomic<double> solve_us_max{0.0};
  // The same over the whole run (never reset), us.
  std::atomic<double> state_us_peak{0.0};
  std::atomic<double> solve_us_peak{0.0};
};

class HapticLoop {
 public:
  explicit HapticLoop(const HapticSetup& setup);

  // A new DeformationState: centres and radii from its positions, tree
  // refit, tissue-obstacle contacts, and the index of its compliance
  // spheres. Returns false (state ignored) if it does not fit the mesh.
  bool take_state(const msg::DeformationState& state);

  // Answers `pose`. `state` is the newest DeformationState (the one last
  // given to take_state), or null before the first.
  void tick(const msg::DevicePose& pose, const msg::DeformationState* state, msg::ForceCommand& command,
            msg::ContactSet& contacts);

  const contact::ContactResponse& response() const { return response_; }
  const LoopMetrics& metrics() const { return metrics_; }
  // Also resets the per-report maxima (reporter thread).
  void append_metrics(std::vector<std::pair<std::string, double>>& out);

 private:
  contact::DeviceSample device_sample(const msg::DevicePose& pose);
  void collect_rows(const msg::DeformationState* state);
  void query_obstacles();

  const HapticSetup& setup_;
  double nominal_period_s_;
  contact::ContactResponse response_;
  haptic::SphereState spheres_;
  haptic::SphereTree tree_;
  std::vector<double> positions_m_;  // float wire positions widened for SphereState

  // Tool.
  haptic::RigidBody tool_body_;
  haptic::QuerySettings tool_query_;
  haptic::PrePenetrationMemory tool_memory_;
  haptic::ContactBuffer tool_contacts_;
  std::vector<std::uint32_t> order_;  // indices into tool_contacts_, deepest first when over capacity
  std::vector<contact::ContactRow> rows_;
  std::size_t row_count_ = 0;

  // Obstacles (tissue side, always hard): queried once per FEM state.
  std::vector<haptic::RigidBody> obstacle_bodies_;
  std::vector<haptic::PrePenetrationMemory> obstacle_memory_;
  haptic::QuerySettings obstacle_query_;
  haptic::ContactBuffer obstacle_buffer_;
  std::vector<fem::Contact> obstacle_contacts_;
  std::vector<std::uint32_t> obstacle_body_ids_;
  std::size_t obstacle_count_ = 0;

  // Compliance sphere index per sphere id for the newest state (-1: none).
  std::vector<std::int32_t> compliance_index_;
  std::vector<std::uint32_t> indexed_ids_;  // ids set in compliance_index_, to clear them again
  std::size_t indexed_count_ = 0;
  bool have_free_centres_ = false;

  bool started_ = false;
  bool was_lost_ = false;
  std::uint64_t last_servo_tick_ = 0;
  std::uint64_t tick_ = 0;
  LoopMetrics metrics_;
};

}  // namespace fahr::haptic_service
