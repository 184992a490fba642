// One haptic tick per DevicePose: the tool's contacts with the tongue
// through the AIST of the newest digested FEM state (TissueSnapshot), its
// contacts with the rigid anatomy through its surface samples, the contact
// response on the FEM's compliance, and the ForceCommand and ContactSet that
// answer it. Every buffer is sized in the constructor; tick() allocates
// nothing once the wire samples hold their reserved capacity.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "contact_set.h"
#include "device_pose.h"
#include "fahr/collision/contact_buffer.h"
#include "fahr/collision/deepest_contacts.h"
#include "fahr/collision/rigid_body.h"
#include "fahr/collision/sphere_query.h"
#include "fahr/collision/surface_samples.h"
#include "fahr/contact/contact_response.h"
#include "fahr/contact/penalty_response.h"
#include "fahr/haptic_service/haptic_setup.h"
#include "fahr/haptic_service/tissue_snapshot.h"
#include "force_command.h"

namespace fahr::haptic_service {

// Figures the reporter thread reads while the loop runs (relaxed atomics:
// each is a single value, no invariant ties them together).
struct LoopMetrics {
  std::atomic<std::uint64_t> ticks{0};
  std::atomic<std::uint64_t> snapshots{0};  // distinct FEM states the ticks used
  std::atomic<std::uint32_t> tool_rows{
      0};  // tissue rows of the last tick (touching and candidates)
  std::atomic<std::uint32_t> anatomy_rows{0};     // tool vs rigid anatomy rows of the last tick
  std::atomic<std::uint32_t> active_contacts{0};  // rows with lambda > 0, last tick
  std::atomic<std::uint64_t> rows_dropped{0};     // contacts within the row margin not rows, total
  std::atomic<std::uint64_t> query_overflows{0};  // contact buffer full, total
  std::atomic<std::uint32_t> missing_compliance{0};  // rows without tissue compliance, last tick
  std::atomic<std::uint64_t> tissue_rows_total{0};   // tissue rows solved, all ticks
  std::atomic<std::uint64_t> rows_without_compliance{0};  // of those, rows without W, total
  // Of those, the ones touching the tool (depth > 0; the others are
  // candidates within the margin), total.
  std::atomic<std::uint64_t> rows_without_compliance_touching{0};
  std::atomic<std::uint64_t> lost_track_ticks{0};
  // Ticks whose rows' A from the FEM's W was indefinite and had its
  // diagonal scaled (contact::ContactSolver::load), and the largest scale.
  std::atomic<std::uint64_t> indefinite_w_ticks{0};
  std::atomic<double> w_diagonal_scale_max{1.0};
  // Ticks whose coupled solve's step was refused (the proxy held).
  std::atomic<std::uint64_t> refused_steps{0};
  std::atomic<std::uint64_t> tissue_resets{0};   // new DeformationState reset epochs seen
  std::atomic<std::uint64_t> tissue_losses{0};   // episodes without a usable FEM state
  std::atomic<std::uint64_t> tissue_returns{0};  // ends of those episodes
  std::atomic<std::uint64_t> fem_writers{0};     // FEM writers after the first (restarts)
  std::atomic<std::uint64_t> tissue_lost_ticks{0};
  std::atomic<std::uint64_t> device_idle_ticks{0};  // device disabled or engaging: zero commanded
  std::atomic<std::uint64_t> device_silences{0};    // episodes without a DevicePose (real time)
  std::atomic<std::uint64_t> lost_track_episodes{0};
  std::atomic<double> reaction_n{0.0};  // last tissue reaction, N
  std::atomic<double> obstacle_reaction_n{
      0.0};                               // last reaction of the rigid anatomy on the tool, N
  std::atomic<double> peak_force_n{0.0};  // largest |F_k| commanded, N
  // Work time of a tick (query, solve, messages): largest since the last
  // report (the reporter resets it) and over the whole run, us.
  std::atomic<double> tick_us_max{0.0};
  std::atomic<double> tick_us_peak{0.0};
};

// The W figures of a run, one sentence: ticks whose rows' A needed its
// diagonal scaled and the largest scale, coupled steps refused, rows
// without W.
std::string w_summary(const LoopMetrics& m);

// Where the last tick's time went (steady clock, us): finding the tool's
// contacts with the tissue (AIST query or triangle baseline, and the row
// selection), with the rigid anatomy, and the contact response (solve,
// decision, ContactSet). Read in the loop's thread (benchmarks, stack_sim).
struct TickPhases {
  double tissue_query_us = 0.0;
  double anatomy_query_us = 0.0;
  double response_us = 0.0;
  collision::QueryStats tissue_query;  // the AIST query's work (zero with the triangle baseline)
};

// Rows the tool may have against rigid anatomy per tick: one per tool
// sample within the margin, the deepest kept.
inline constexpr std::size_t kMaxAnatomyRows = 16;
// The FEM's compliance block (the scene's solver.max_candidate_contacts, at
// most msg::MAX_COMPLIANCE_SPHERES) holds the tick's rows and, in the slots
// left, the contacts nearest to becoming rows: W arrives one or two FEM
// periods after a sphere enters the block, so it must be there before the
// sphere is deep enough to be a row. At least this many slots (a third of a
// smaller block) are kept for them; the rows take the rest, up to the
// solve's cap.
// With several deformable bodies one block's worth is shared by all of
// them, though each body's FEM could hold a block of its own.
inline constexpr std::size_t kComplianceLookAhead = 32;
// Largest change of the commanded force a tick after the tongue was reset
// (DeformationState::reset_epoch), a new FEM writer appeared, the tissue
// came back after a loss or the device (re-)engaged; and while the force
// ramps down after a loss, N.
inline constexpr double kResetSlewN = 0.1;
// Ticks a slew lasts at least: the force it follows is small right after a
// reset and grows as the proxy settles and the contacts come back.
inline constexpr std::uint32_t kSlewWindowTicks = 200;
// Real time: no usable DeformationState for this long and the tissue is
// lost (the FEM steps every 5 ms; ten steps missing are not jitter).
inline constexpr std::int64_t kTissueLossTimeoutNs = 50'000'000;
// Servo ticks over which the force ramps from its value at the loss to
// zero (150 ms at 1 kHz); each command still changes by at most kResetSlewN.
inline constexpr double kLossRampTicks = 150.0;

// Several deformable bodies: the tick's ContactSet of the joined tissue
// (sphere ids of HapticSetup::layout) as one set per body, out[b] for
// HapticSetup::bodies[b]: its contacts in the tick's order with the body's
// own sphere ids, its layout's fingerprint and the FEM step of its state;
// the tool's pose, state and header as the tick's. Allocation-free while
// each out[b] holds msg::MAX_CONTACTS.
void split_contacts(const HapticSetup& setup, const TissueSnapshot& tissue,
                    const msg::ContactSet& joined, std::span<msg::ContactSet* const> out);

class HapticLoop {
 public:
  explicit HapticLoop(const HapticSetup& setup);

  // Answers `pose` on the tissue of `tissue` (the newest snapshot).
  // `tissue_lost`: the FEM has sent no usable state for kTissueLossTimeoutNs
  // (real time only): the tongue is not rendered, the force ramps to zero
  // and the ContactSet is empty until a state comes again; the force then
  // resumes through the reset slew.
  void tick(const msg::DevicePose& pose, const TissueSnapshot& tissue, msg::ForceCommand& command,
            msg::ContactSet& contacts, bool tissue_lost = false);

  const HapticSetup& setup() const { return setup_; }
  const contact::ContactResponse& response() const { return response_; }
  const LoopMetrics& metrics() const { return metrics_; }
  const TickPhases& last_phases() const { return phases_; }
  // SphereLayout::fingerprint() of the setup's layout, in every ContactSet.
  std::uint64_t layout_fingerprint() const { return layout_fingerprint_; }
  // Also resets the per-report maxima (reporter thread).
  void append_metrics(std::vector<std::pair<std::string, double>>& out);
  // Real time: no DevicePose for kTissueLossTimeoutNs (the loop's thread).
  void note_device_silence() { metrics_.device_silences.fetch_add(1, std::memory_order_relaxed); }
  // What changed since the last call, one sentence each (the tissue lost,
  // back, a new FEM writer, the device silent): the reporter's thread, for
  // ServiceEvents.
  void take_errors(std::vector<std::string>& errors);

 private:
  contact::DeviceSample device_sample(const msg::DevicePose& pose);
  void collect_tissue_rows(const TissueSnapshot& tissue);
  void fill_tool_contacts(std::span<const fem::Contact> requests, const TissueSnapshot& tissue,
                          msg::ContactSet& contacts) const;
  void select_rows(const TissueSnapshot& tissue);
  void collect_triangle_rows(const TissueSnapshot& tissue);
  void collect_anatomy_rows(const Eigen::Isometry3d& world_from_tool);
  void slew_force(msg::ForceCommand& command);
  void begin_resume(const contact::DeviceSample& device);
  void lost_tick(const msg::DevicePose& pose, const contact::DeviceSample& device,
                 const TissueSnapshot& tissue, msg::ForceCommand& command,
                 msg::ContactSet& contacts);
  const contact::ForceOutput& penalty_tick(const contact::DeviceSample& device,
                                           const TissueSnapshot& tissue);

  const HapticSetup& setup_;
  std::uint64_t layout_fingerprint_;
  double nominal_period_s_;
  contact::ContactResponse response_;
  // The penalty baseline (setup.penalty) and its ContactSet entries.
  contact::PenaltyResponse penalty_;
  std::vector<fem::Contact> penalty_contacts_;
  std::size_t penalty_count_ = 0;

  // Tool against the tongue (AIST).
  collision::RigidBody tool_body_;
  collision::QuerySettings tool_query_;
  collision::PrePenetrationMemory tool_memory_;
  collision::ContactBuffer tool_contacts_;
  std::vector<std::uint32_t>
      order_;                    // indices into tool_contacts_, deepest first when over capacity
  std::vector<double> row_key_;  // per contact: select_rows' key
  std::vector<std::uint32_t> order_scratch_;  // select_rows: contacts with W
  // Per W sphere (compliance index): its free-motion depth, taken on the
  // first tick of its FEM state, and that state (step, writer, reset epoch).
  std::vector<double> free_depth_m_;
  std::uint64_t free_depth_step_ = 0;
  std::uint32_t free_depth_writer_ = 0;
  std::uint32_t free_depth_epoch_ = 0;
  bool free_depth_valid_ = false;
  std::vector<std::uint32_t> request_of_;  // select_rows: the block's other contacts
  std::vector<fem::Contact> requests_;     // this tick's contacts asked for W
  std::size_t row_pick_ = 0;               // rows select_rows took
  std::size_t request_count_ = 0;          // requests this tick
  std::size_t rows_without_w_ = 0;         // contacts deep enough to be rows, without W
  std::size_t touching_without_w_ = 0;     // of those, touching the tool
  // Tool against the tongue (the triangle baseline, CollisionMethod::kTriangle).
  std::vector<collision::TriangleContact> triangle_contacts_;
  std::vector<std::int32_t> row_of_sphere_;    // per sphere: its slot in sphere_contact_, or -1
  std::vector<std::uint32_t> sphere_contact_;  // per slot: the deepest triangle contact of a sphere
  std::vector<std::uint32_t> slot_sphere_;     // per slot: the sphere (to clear row_of_sphere_)
  // Tool against the rigid anatomy (surface samples).
  std::vector<collision::RigidBody> anatomy_bodies_;
  std::vector<collision::SurfaceContact> anatomy_contacts_;
  std::vector<std::uint32_t> anatomy_order_;
  std::size_t compliance_block_ = 0;  // spheres in the FEM's W block
  std::size_t tissue_row_budget_ = 0;
  double row_margin_m_ = 0.0;  // HapticSetup::row_margin_m, within the candidate margin
  std::vector<contact::ContactRow> rows_;
  std::size_t row_count_ = 0;

  std::uint64_t last_fem_step_ = 0;
  std::uint32_t reset_epoch_ = 0;
  std::uint32_t fem_writer_ = 0;  // 0 until the first FEM state
  bool slewing_ = false;          // after a reset, until the force caught up
  std::uint32_t slew_ticks_left_ = 0;
  bool tissue_lost_ = false;
  Eigen::Vector3d loss_from_n_ = Eigen::Vector3d::Zero();  // the force when the tissue was lost
  std::uint64_t loss_servo_tick_ = 0;
  bool device_idle_ = false;  // the last pose said the device renders nothing
  Eigen::Vector3d rendered_n_ = Eigen::Vector3d::Zero();  // the last command's force
  bool started_ = false;
  bool was_lost_ = false;
  std::uint64_t last_servo_tick_ = 0;
  std::uint64_t tick_ = 0;
  LoopMetrics metrics_;
  TickPhases phases_;
  // What take_errors() has said (the reporter's thread only).
  std::uint64_t losses_said_ = 0, returns_said_ = 0, writers_said_ = 0, silences_said_ = 0;
};

}  // namespace fahr::haptic_service
