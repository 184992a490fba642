// The haptic contact response of one rigid tool, one tick per DevicePose:
// the contact solve on the FEM's compliance, the force-aware decision, the
// tool proxy, and what ForceCommand and ContactSet need. Everything is
// sized at construction; tick() allocates nothing (a test proves it).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "fahr/contact/contact_row.h"
#include "fahr/contact/contact_solver.h"
#include "fahr/contact/coupling.h"
#include "fahr/contact/force_aware.h"
#include "fahr/contact/force_output.h"
#include "fahr/contact/pgs.h"
#include "fahr/contact/tissue_compliance.h"
#include "fahr/contact/tool_proxy.h"
#include "fahr/fem/contact_set.h"

namespace fahr::contact {

enum class ResponseMode : std::uint8_t {
  // Rows yield with the FEM's compliance W; force-aware. The rows' tissue
  // centres must be the FEM's free-motion centres (docs/design/contact-contract.md).
  kCompliance,
  // The naive loop for comparison: the same solve with W = 0 on the newest
  // FEM positions (the published, projected centres), the tissue pushed by
  // the tool at the device pose; never freezes.
  kNaive,
};

struct ResponseSettings {
  ResponseMode mode = ResponseMode::kCompliance;
  CouplingSettings coupling;
  ForceAwareSettings force_aware;
  PgsSettings pgs;
  std::size_t max_rows = 64;  // rows solved per tick (tool vs spheres and obstacles)
  std::size_t max_contacts =
      256;  // ContactSet entries per tick, incl. held spheres and obstacle contacts
  std::size_t max_holds = 64;  // spheres held while frozen
};

// One DevicePose as the response needs it (world frame).
struct DeviceSample {
  std::uint64_t pose_seq = 0;                            // DevicePose header.seq
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // stylus (after workspace mapping), m
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // world_from_stylus, unit
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();           // m/s
  double renderable_force_n = 3.0;    // what the device can render now, N, >= 0
  double max_stiffness_npm = 1480.0;  // highest stable stiffness, N/m, > 0 (Touch X: 1480)
  double dt_s = 0.001;                // since the previous tick, s, > 0
};

struct TickInput {
  DeviceSample device;
  // Rows measured with the tool at proxy().position_m and the device's
  // orientation (the reference pose p0 of the solve).
  std::span<const ContactRow> rows;
  TissueCompliance compliance;
  // Tissue spheres against rigid obstacles (always hard), found by the
  // collision stage: copied into the ContactSet after the tool contacts.
  std::span<const fem::Contact> tissue_obstacle_contacts;
};

struct TickReport {
  TrackingState state = TrackingState::kTracking;
  SolverLoadReport load;
  PgsReport pgs;
  PgsWork pgs_work;                   // all of this tick's solves
  bool contacts_overflow = false;     // ContactSet entries dropped
  bool holds_overflow = false;        // spheres not held while frozen
  bool catch_up_limited = false;      // the proxy moved at the catch-up speed bound
  bool yielded = false;               // a held proxy backed off to keep the reaction at the limit
  bool implausible_step = false;      // the coupled solve's step was refused; the proxy held
  bool tissue_force_clamped = false;  // the tissue forces were scaled down to the limit
  // HeldProxy::kStay or kHoldLoad: the held tool's tissue forces were
  // scaled down to the limit (kStay's spheres stay frozen, kHoldLoad's
  // entries are force only: tissue_held_by_load).
  bool tissue_force_scaled_held = false;
  // HeldProxy::kHoldLoad: the tool's entries are force only, the tissue held
  // by its load (while held, or catching up with the load scaled).
  bool tissue_held_by_load = false;
  bool force_limited = false;        // the commanded force was scaled to the renderable force
  double obstacle_reaction_n = 0.0;  // |force of rigid obstacles on the tool|, N
  // Wall time of the tick's parts, us: the rows' Delassus matrix and its
  // semidefinite check (ContactSolver::load); the proxy's move (the coupled
  // or pinned solves, the obstacles); the output (forces, local stiffness,
  // the ContactSet's entries).
  double load_us = 0.0;
  double move_us = 0.0;
  double output_us = 0.0;
};

class ContactResponse {
 public:
  explicit ContactResponse(const ResponseSettings& settings);

  // Puts the proxy at the device pose, tracking, no contacts.
  void reset(const Eigen::Vector3d& position_m, const Eigen::Quaterniond& orientation);

  // The tissue as several bodies: body b's rows are those whose id lies in
  // [first_ids[b], first_ids[b + 1]) (the last body's run to the end). The
  // tissue's load is then the sum of each body's resultant, so a tool
  // squeezed between two bodies cannot hand each more than the device can
  // render while their resultants cancel. Ascending, first_ids[0] == 0, at
  // most kMaxTissueBodies (std::invalid_argument otherwise); fewer than two:
  // one body, the whole tissue's resultant.
  static constexpr std::size_t kMaxTissueBodies = 8;
  void set_tissue_bodies(std::span<const std::uint32_t> first_ids);

  const ForceOutput& tick(const TickInput& input);

  const ToolProxy& proxy() const { return proxy_; }
  TrackingState state() const { return state_; }
  bool tool_frozen() const { return state_ == TrackingState::kLostTrack; }
  // The ContactSet of the last tick, ordered: tool contacts in row order,
  // held spheres no longer in the rows, then the obstacle contacts.
  std::span<const fem::Contact> contacts() const { return {contacts_.data(), contact_count_}; }
  const ForceOutput& output() const { return output_; }
  const TickReport& report() const { return report_; }
  const ResponseSettings& settings() const { return settings_; }
  // The last tick's rows and their forces (for diagnostics).
  const ContactSolver& solver() const { return solver_; }

 private:
  struct Hold {
    std::uint32_t sphere_id = 0;
    Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d plane_point_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d normal = Eigen::Vector3d::UnitY();
  };

  // move_proxy() and its phases (contact_response.cpp).
  Eigen::Vector3d move_proxy(const TickInput& input, const EffectiveCoupling& coupling);
  std::optional<Eigen::Vector3d> held_step(const TickInput& input,
                                           const EffectiveCoupling& coupling, double pull);
  bool releases_position_hold(const DeviceSample& device, const EffectiveCoupling& coupling);
  Eigen::Vector3d hold_after_implausible_step(double limit);
  Eigen::Vector3d bound_catch_up(const Eigen::Vector3d& step, const DeviceSample& device);
  bool freezes(double pull, double limit) const;
  Eigen::Vector3d freeze(const TissueCompliance& compliance, double limit);
  bool holds_load() const { return settings_.force_aware.held_proxy == HeldProxy::kHoldLoad; }
  // The pinned solve's `facing` while a held tool holds the tissue by a
  // load: the push it froze with; zero otherwise (every row takes part).
  Eigen::Vector3d held_load_facing() const;
  // tick()'s phases after the proxy moved.
  Eigen::Vector3d keep_out_of_bone(const Eigen::Vector3d& step);
  void fill_output(const DeviceSample& device, const EffectiveCoupling& coupling);
  double scale_tissue_forces(const DeviceSample& device);
  // The load the tissue's rows put on the tissue, N: the resultant's norm,
  // or with several bodies the sum of theirs.
  double tissue_load(double resultant_norm) const;
  // The tissue rows' forces summed as magnitudes, N.
  double tissue_magnitudes() const;
  // The proxy does not follow the device this tick (held, or its catch-up bounded).
  bool pinned() const { return state_ == TrackingState::kLostTrack || report_.catch_up_limited; }
  Eigen::Vector3d catch_up_step(const Eigen::Vector3d& toward, double max_step, double dt_s) const;
  Eigen::Vector3d yield_to_limit(const Eigen::Vector3d& offset_m, double limit_n);
  bool plausible_step(const Eigen::Vector3d& step_m, const Eigen::Vector3d& target_offset_m) const;
  void capture_holds(const TissueCompliance& compliance);
  const Hold* find_hold(std::uint32_t sphere_id) const;
  void write_contacts(const TickInput& input, const Eigen::Vector3d& plane_shift_m);
  void push_contact(const fem::Contact& contact);

  ResponseSettings settings_;
  ContactSolver solver_;
  ToolProxy proxy_;
  TrackingState state_ = TrackingState::kTracking;
  double previous_reaction_n_ = 0.0;
  // Unit direction in which the held tool pushed the tissue when it froze
  // (the tissue reaction's resultant on the tissue): kHoldLoad releases when
  // the hand's pull along it falls below the band.
  Eigen::Vector3d held_push_direction_ = Eigen::Vector3d::Zero();
  double tissue_force_scale_ = 1.0;  // applied to the ContactSet's tissue forces this tick
  std::array<std::uint32_t, kMaxTissueBodies> body_first_ids_{};
  std::size_t body_count_ = 1;
  std::vector<Hold> holds_;
  std::size_t hold_count_ = 0;
  std::vector<fem::Contact> contacts_;
  std::size_t contact_count_ = 0;
  ForceOutput output_;
  TickReport report_;
};

}  // namespace fahr::contact
