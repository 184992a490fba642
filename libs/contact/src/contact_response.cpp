// One haptic tick: coupling, contact solve, force-aware decision, proxy,
// ForceCommand fields and the ContactSet for the FEM.
#include "fahr/contact/contact_response.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "fahr/contact/force_limit.h"

namespace fahr::contact {
namespace {

// Regula falsi steps of yield_to_limit; each is one pinned PGS solve, and
// the reaction is nearly linear in the back-off, so a few reach the
// tolerance; 8 bound the rare strongly curved case.
constexpr int kMaxYieldIterations = 8;
// How much farther than its deepest row a stepping proxy may go, m: 1 mm,
// a tick of a fast hand.
constexpr double kYieldCapMarginM = 1e-3;
// How far a held proxy may back off in one tick, m: 1 mm, a tick of a fast
// hand (0.4 N of coupling force at 400 N/m). The rows' depths are those of
// the FEM's free motion, which lies far beyond the blade once the tongue is
// pressed in deep; a back-off bounded by them threw the blade through the
// tongue in one tick (the overshoot bench; reproduced by
// ForceAware.ATickNeverThrowsAHeldToolFartherThanAFastHandMoves: 23 mm).
constexpr double kMaxYieldStepM = 1e-3;
// Share of the tissue's load on rows that push against the resultant above
// which the tool counts as gripped (tissue on more than one side): backing
// off along the resultant then deepens a quarter or more of the load.
constexpr double kGrippedLoadShare = 0.25;
// A row counts as pushing against the resultant when its normal is within
// 60 degrees of the back-off: rows beside the tool (a rounded tool sunk in
// a block) are not a grip.
constexpr double kBehindCosine = 0.5;
// kHoldLoad: a hand whose pull lies more than 60 degrees from the push the
// tool froze with is not pressing into the tissue along it (move_proxy).
constexpr double kPressingCosine = 0.5;
// A tissue reaction above this multiple of the limit is not the force-aware
// decision's rounding but a wedge (see tick()): the targets' 5 % band.
constexpr double kWedgeBand = 1.05;
// Relative band around the limit the back-off aims for: 0.1 %, far below
// what the 5 % target allows and what a hand feels.
constexpr double kYieldTolerance = 1e-3;

}  // namespace

ContactResponse::ContactResponse(const ResponseSettings& settings)
    : settings_(settings),
      solver_(settings.max_rows),
      holds_(settings.max_holds),
      contacts_(settings.max_contacts) {
  if (settings_.mode == ResponseMode::kNaive) settings_.force_aware.enabled = false;
}

void ContactResponse::reset(const Eigen::Vector3d& position_m,
                            const Eigen::Quaterniond& orientation) {
  proxy_ = ToolProxy{position_m, orientation, Eigen::Vector3d::Zero()};
  state_ = TrackingState::kTracking;
  previous_reaction_n_ = 0.0;
  held_push_direction_ = Eigen::Vector3d::Zero();
  hold_count_ = 0;
  contact_count_ = 0;
  solver_.clear_warm_start();
  output_ = ForceOutput{};
  report_ = TickReport{};
}

const ContactResponse::Hold* ContactResponse::find_hold(std::uint32_t sphere_id) const {
  for (std::size_t h = 0; h < hold_count_; ++h) {
    if (holds_[h].sphere_id == sphere_id) return &holds_[h];
  }
  return nullptr;
}

// Freezing holds each loaded sphere where the pinned solve says the tool
// keeps it: c' = c_free + sum_j W_ij n_j lambda_j (the paper's c' = c, with
// c the constrained centre, not the free one the rows carry).
void ContactResponse::capture_holds(const TissueCompliance& compliance) {
  hold_count_ = 0;
  report_.holds_overflow = false;
  for (std::size_t i = 0; i < solver_.size(); ++i) {
    const ContactRow& row = solver_.row(i);
    if (row.kind != RowKind::kTissue || !(solver_.lambda(i) > 0.0 || solver_.penetration(i) > 0.0))
      continue;
    if (hold_count_ == holds_.size()) {
      report_.holds_overflow = true;
      break;
    }
    holds_[hold_count_++] =
        Hold{row.id, row.other_point_m + solver_.predicted_motion(i, compliance), row.tool_point_m,
             row.normal};
  }
}

// A held tool whose tissue reaction exceeds the limit (the tissue state
// changed under it, or the hand eased off slower than the tissue relaxes)
// backs off along the reaction until the reaction is the limit: the tissue
// never receives more than the device can render. The reaction falls
// monotonically as the tool backs off, so the back-off s is bracketed in
// [0, cap] and found by regula falsi (Illinois) on the pinned solve. The cap
// is a tick of a fast hand (kMaxYieldStepM); a back-off that needs more
// takes the cap and goes on next tick. A tool the tissue grips from more
// than one side (the blade sunk into a tongue that closes over it) does not
// back off at all: the resultant is then a small difference of large forces,
// backing off along it deepens the rows on the other side, and the reaction
// need not fall; the proxy stays, and tick() scales what the tissue receives
// to the limit.
Eigen::Vector3d ContactResponse::yield_to_limit(const Eigen::Vector3d& offset_m, double limit_n) {
  const Eigen::Vector3d reaction = solver_.resultant(RowKind::kTissue);
  const double r0 = reaction.norm();
  if (!(r0 > limit_n)) return offset_m;
  report_.yielded = true;
  const Eigen::Vector3d out = -reaction / r0;  // the tissue pushes the tool this way
  double load = 0.0, opposing = 0.0;
  for (std::size_t i = 0; i < solver_.size(); ++i) {
    if (solver_.row(i).kind != RowKind::kTissue) continue;
    load += solver_.lambda(i);
    // Backing off deepens this row by more than half as much: tissue behind.
    if (solver_.row(i).normal.dot(out) > kBehindCosine) opposing += solver_.lambda(i);
  }
  if (opposing > kGrippedLoadShare * load) return offset_m;  // gripped: hold
  const auto excess = [&](double s) {
    solver_.solve_pinned(offset_m + s * out, settings_.pgs);
    return solver_.resultant(RowKind::kTissue).norm() - limit_n;
  };
  double lo = 0.0, f_lo = r0 - limit_n;
  double hi = kMaxYieldStepM;
  double f_hi = excess(hi);
  if (f_hi > 0.0) return offset_m + hi * out;  // the most one tick allows
  int stale_side = 0;                          // Illinois: halve the value kept twice in a row
  for (int iteration = 0; iteration < kMaxYieldIterations; ++iteration) {
    const double s = hi - f_hi * (hi - lo) / (f_hi - f_lo);
    const double f = excess(s);
    if (std::abs(f) <= kYieldTolerance * limit_n && f <= 0.0) return offset_m + s * out;
    if (f > 0.0) {
      lo = s;
      f_lo = f;
      if (stale_side == 1) f_hi *= 0.5;
      stale_side = 1;
    } else {
      hi = s;
      f_hi = f;
      if (stale_side == -1) f_lo *= 0.5;
      stale_side = -1;
    }
  }
  // Never leave the tissue above the limit: end on the side below it.
  excess(hi);
  return offset_m + hi * out;
}

// The coupled solve's step is implausible when it moves the proxy farther
// than the hand's pull plus the deepest row plus a margin: no equilibrium
// lies beyond that, so an unconverged or infeasible solve (the tool pinched
// between bone and tissue) produced it.
bool ContactResponse::plausible_step(const Eigen::Vector3d& step_m,
                                     const Eigen::Vector3d& target_offset_m) const {
  double deepest = 0.0;
  for (std::size_t i = 0; i < solver_.size(); ++i)
    deepest = std::max(deepest, solver_.penetration(i));
  return step_m.allFinite() && step_m.norm() <= target_offset_m.norm() + deepest + kYieldCapMarginM;
}

// A catch-up step toward `toward` (the coupled equilibrium's offset): at
// most max_step long, and differing from the proxy's last step by at most
// the catch-up acceleration times dt^2.
Eigen::Vector3d ContactResponse::catch_up_step(const Eigen::Vector3d& toward, double max_step,
                                               double dt_s) const {
  const Eigen::Vector3d last = proxy_.velocity_mps * dt_s;
  Eigen::Vector3d turn = toward * (max_step / toward.norm()) - last;
  const double max_turn = settings_.force_aware.catch_up_acceleration_mps2 * dt_s * dt_s;
  if (turn.norm() > max_turn) turn *= max_turn / turn.norm();
  Eigen::Vector3d step = last + turn;
  if (step.norm() > max_step) step *= max_step / step.norm();
  return step;
}

// Where the proxy goes this tick, as an offset from where it is, and the
// tracking state after it. Each phase leaves the solve at the proxy's new
// place (tick() reads its forces): held while lost track, or released; the
// coupled solve's step; the catch-up's bound; the freeze.
Eigen::Vector3d ContactResponse::move_proxy(const TickInput& input,
                                            const EffectiveCoupling& coupling) {
  const DeviceSample& device = input.device;
  const double limit = device.renderable_force_n;
  // kHoldLoad decides on the hand's pull into the tissue along the push the
  // tool froze with: a hand pressing on keeps the tool held, one that eases
  // off or draws back out (the spring then stretches the other way) releases
  // it, and one that presses past the limit again while the proxy catches up
  // holds it again. No solve decides it, so the state does not flicker with
  // the rows or with a tissue still relaxing under the released tool. A
  // hand whose pull points mostly elsewhere is not pressing on, whatever
  // its component along that push: a blade the tissue pushed sideways
  // while it sank, drawn up and out of the mouth, kept a sideways stretch
  // of the spring past the limit and was held for as long as the hand
  // stayed out (docs/design/force-aware-decision.md).
  const Eigen::Vector3d stretch = coupling.stiffness_npm * (device.position_m - proxy_.position_m);
  const double along = stretch.dot(held_push_direction_);
  const double pull = along >= kPressingCosine * stretch.norm() ? along : std::min(along, 0.0);
  if (state_ == TrackingState::kLostTrack) {
    if (const std::optional<Eigen::Vector3d> held = held_step(input, coupling, pull)) return *held;
    state_ = TrackingState::kCatchingUp;
  }
  const Eigen::Vector3d target_offset = coupling.target_m - proxy_.position_m;
  Eigen::Vector3d step =
      solver_.solve_coupled(coupling.effective_stiffness_npm, target_offset, settings_.pgs);
  if (!plausible_step(step, target_offset)) return hold_after_implausible_step(limit);
  if (state_ == TrackingState::kCatchingUp) step = bound_catch_up(step, device);
  if (freezes(pull, limit)) return freeze(input.compliance, limit);
  return step;
}

// While the device has lost track: the held proxy's step this tick, or
// nothing once the hold is released (the proxy then catches up).
std::optional<Eigen::Vector3d> ContactResponse::held_step(const TickInput& input,
                                                          const EffectiveCoupling& coupling,
                                                          double pull) {
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  const double limit = input.device.renderable_force_n;
  const bool release = holds_load() ? should_release(settings_.force_aware, pull, limit)
                                    : releases_position_hold(input.device, coupling);
  if (release) return std::nullopt;
  solver_.solve_pinned(zero, settings_.pgs, held_load_facing());
  if (settings_.force_aware.held_proxy != HeldProxy::kBackOff) return zero;
  const Eigen::Vector3d back = yield_to_limit(zero, limit);
  if (back != zero) capture_holds(input.compliance);
  return back;
}

// kHoldLoad, held: the pinned solve loads only the tissue the tool pushes
// along the push it froze with. A load keeps no geometry, so tissue beside
// the blade closes over its plate; rows on that tissue face against the
// push, and a solve over both faces asks for forces that push the two
// layers apart and cancel in the resultant. Bounded as a sum by the limit
// (scale_tissue_forces), they starved the push: the held tissue got 4 % of
// the limit on the neonatal tongue and 0.7 % on the ArtiSynth tongue while
// the hand felt all of it (docs/design/force-aware-decision.md).
Eigen::Vector3d ContactResponse::held_load_facing() const {
  return holds_load() && state_ == TrackingState::kLostTrack ? held_push_direction_
                                                             : Eigen::Vector3d::Zero();
}

// kStay and kBackOff release when the coupling spring falls within the
// band, or when tracking again would load the tissue within it.
bool ContactResponse::releases_position_hold(const DeviceSample& device,
                                             const EffectiveCoupling& coupling) {
  const double limit = device.renderable_force_n;
  const double spring = coupling.stiffness_npm * (device.position_m - proxy_.position_m).norm();
  if (should_release(settings_.force_aware, spring, limit)) return true;
  // The spring alone cannot tell a hand still pushing in from one that has
  // drawn back out of the tissue (or the mouth): both stretch it.
  solver_.solve_coupled(coupling.effective_stiffness_npm, coupling.target_m - proxy_.position_m,
                        settings_.pgs);
  return should_release(settings_.force_aware, solver_.resultant(RowKind::kTissue).norm(), limit);
}

// The coupled solve's step was refused: hold the tool this tick (the pinned
// solve is well posed: no coupling term) rather than jump; the next tick's
// warm start solves from here.
Eigen::Vector3d ContactResponse::hold_after_implausible_step(double limit) {
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  report_.implausible_step = true;
  // The refused solve's lambda is no start for this one.
  solver_.clear_lambda();
  solver_.solve_pinned(zero, settings_.pgs, held_load_facing());
  return holds_load() ? zero : yield_to_limit(zero, limit);
}

// Reactivated: the equilibrium may be a few mm away (the tissue relaxed
// while the hand eased off); go there at a bounded speed so the force
// changes smoothly, holding the tool where the bound leaves it. Tracking
// again once the equilibrium is within one bounded step.
Eigen::Vector3d ContactResponse::bound_catch_up(const Eigen::Vector3d& step,
                                                const DeviceSample& device) {
  const double max_step = settings_.force_aware.catch_up_speed_mps * device.dt_s;
  if (!(step.norm() > max_step)) {
    state_ = TrackingState::kTracking;
    return step;
  }
  Eigen::Vector3d bounded = catch_up_step(step, max_step, device.dt_s);
  solver_.solve_pinned(bounded, settings_.pgs);
  // kHoldLoad never backs off: a back-off is not bounded by the catch-up
  // speed, and tick() scales what the tissue receives instead.
  if (!holds_load()) bounded = yield_to_limit(bounded, device.renderable_force_n);
  report_.catch_up_limited = true;
  return bounded;
}

// While catching up the tissue may still push at the frozen level (up to
// the limit and a little over); freeze again only if it grows, i.e. the
// hand pushes back in, so the two states cannot chatter (kHoldLoad: only if
// the hand's pull passes the limit again).
bool ContactResponse::freezes(double pull, double limit) const {
  const double reaction = solver_.resultant(RowKind::kTissue).norm();
  const bool catching_up = state_ == TrackingState::kCatchingUp;
  if (holds_load() && catching_up) return should_freeze(settings_.force_aware, pull, limit);
  const bool growing = !catching_up || reaction > previous_reaction_n_;
  return should_freeze(settings_.force_aware, reaction, limit) && growing;
}

// The proxy stops where it was (the last tick's pose, whose reaction was
// within the limit); kStay and kBackOff hold the loaded spheres there.
Eigen::Vector3d ContactResponse::freeze(const TissueCompliance& compliance, double limit) {
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  state_ = TrackingState::kLostTrack;
  // The push it froze with, over every row (an earlier hold's direction is
  // no guide); then, held by a load, the load along it alone.
  solver_.solve_pinned(zero, settings_.pgs);
  const Eigen::Vector3d push = solver_.resultant(RowKind::kTissue);
  held_push_direction_ =
      push.norm() > 0.0 ? Eigen::Vector3d(push / push.norm()) : Eigen::Vector3d::Zero();
  if (holds_load()) solver_.solve_pinned(zero, settings_.pgs, held_load_facing());
  Eigen::Vector3d back =
      settings_.force_aware.held_proxy == HeldProxy::kBackOff ? yield_to_limit(zero, limit) : zero;
  if (!holds_load()) capture_holds(compliance);  // kHoldLoad holds no sphere
  return back;
}

void ContactResponse::push_contact(const fem::Contact& contact) {
  if (contact_count_ == contacts_.size()) {
    report_.contacts_overflow = true;
    return;
  }
  contacts_[contact_count_++] = contact;
}

void ContactResponse::write_contacts(const TickInput& input, const Eigen::Vector3d& plane_shift_m) {
  contact_count_ = 0;
  const bool frozen = state_ == TrackingState::kLostTrack;
  const bool load_only = report_.tissue_force_clamped || report_.tissue_held_by_load;
  for (std::size_t i = 0; i < solver_.size(); ++i) {
    const ContactRow& row = solver_.row(i);
    if (row.kind != RowKind::kTissue) continue;
    fem::Contact c;
    c.sphere_id = row.id;
    c.kind = fem::ContactKind::kTool;
    c.normal = row.normal;
    c.plane_point_m = row.tool_point_m + plane_shift_m;
    c.penetration_m = solver_.penetration(i) + row.normal.dot(plane_shift_m);
    c.force_n = tissue_force_scale_ * solver_.lambda(i);
    c.hold_centre_m = row.other_point_m;
    const Hold* hold = frozen && !load_only ? find_hold(row.id) : nullptr;
    if (load_only) {
      // Wedged past the limit (bone drives the tool into the tissue): the
      // tissue gets the limited forces and no geometric constraint, which
      // would push it as far as the bone says whatever the force. A tool
      // held by kHoldLoad is held the same way: by its load alone.
      c.kind = fem::ContactKind::kForceOnly;
      c.state = c.force_n > 0.0 ? fem::ContactState::kActive : fem::ContactState::kCandidate;
    } else if (hold != nullptr) {
      c.state = fem::ContactState::kFrozen;
      c.hold_centre_m = hold->centre_m;
    } else if (c.force_n > 0.0 || c.penetration_m > 0.0) {
      c.state = fem::ContactState::kActive;
    } else {
      c.state = fem::ContactState::kCandidate;
    }
    push_contact(c);
  }
  if (frozen && !load_only) {
    // Held spheres the collision stage no longer reports stay held.
    for (std::size_t h = 0; h < hold_count_; ++h) {
      bool listed = false;
      for (std::size_t i = 0; i < solver_.size() && !listed; ++i) {
        listed =
            solver_.row(i).kind == RowKind::kTissue && solver_.row(i).id == holds_[h].sphere_id;
      }
      if (listed) continue;
      fem::Contact c;
      c.sphere_id = holds_[h].sphere_id;
      c.state = fem::ContactState::kFrozen;
      c.normal = holds_[h].normal;
      c.plane_point_m = holds_[h].plane_point_m;
      c.hold_centre_m = holds_[h].centre_m;
      push_contact(c);
    }
  }
  for (const fem::Contact& c : input.tissue_obstacle_contacts) push_contact(c);
}

// A held, backing-off or catching-up proxy was placed by the pinned solve,
// which gives bone no force: keep it out of the bone, and re-solve the
// tissue where it ends up.
Eigen::Vector3d ContactResponse::keep_out_of_bone(const Eigen::Vector3d& step) {
  if (!solver_.has_obstacle_rows() ||
      (state_ == TrackingState::kTracking && !report_.implausible_step))
    return step;
  Eigen::Vector3d kept_out = solver_.project_on_obstacles(step, settings_.pgs);
  if (!kept_out.allFinite() || !((kept_out - step).squaredNorm() > 0.0)) return step;
  solver_.solve_pinned(kept_out, settings_.pgs, held_load_facing());
  return kept_out;
}

// The ForceCommand's fields from the proxy the tick left.
void ContactResponse::fill_output(const DeviceSample& device, const EffectiveCoupling& coupling) {
  ForceOutput& out = output_;
  out.answered_pose_seq = device.pose_seq;
  out.answered_position_m = device.position_m;
  out.force_n = coupling.stiffness_npm * (proxy_.position_m - device.position_m) +
                coupling.damping_nspm * (proxy_.velocity_mps - device.velocity_mps);
  // A pinned proxy does not follow the device: the stylus feels the bare
  // coupling spring. Otherwise the active set's stiffness, <= K_c.
  out.stiffness_npm = pinned()
                          ? Eigen::Matrix3d(coupling.stiffness_npm * Eigen::Matrix3d::Identity())
                          : solver_.local_stiffness(coupling.stiffness_npm);
  report_.force_limited = limit_force(device.renderable_force_n, out.force_n, out.stiffness_npm);
  out.proxy_position_m = proxy_.position_m;
  out.proxy_orientation = proxy_.orientation;
  out.lost_track = state_ == TrackingState::kLostTrack;
  out.device_minus_proxy_m = device.position_m - proxy_.position_m;
}

// What the tissue receives is never more than the device can render: a
// solve that asks for clearly more (the tool wedged between bone and
// tongue, where the bone's rows push it into the tissue) has its tissue
// forces scaled down to the limit and sent as force only. Within the band
// the force-aware decision already keeps the reaction at the limit (to its
// yield tolerance and the one-tick lag), and the constraints stay. Sets
// tissue_force_scale_; returns the solve's own tissue reaction, N.
double ContactResponse::scale_tissue_forces(const DeviceSample& device) {
  const HeldProxy held = settings_.force_aware.held_proxy;
  const double solved_reaction = solver_.resultant(RowKind::kTissue).norm();
  tissue_force_scale_ = 1.0;
  if (settings_.mode == ResponseMode::kNaive) return solved_reaction;
  const double load = tissue_load(solved_reaction);
  const bool holds_proxy = (held == HeldProxy::kStay && state_ == TrackingState::kLostTrack) ||
                           (held == HeldProxy::kHoldLoad && pinned());
  if (holds_proxy) {
    // Held where it froze: the tissue forces are scaled to the limit; the
    // spheres stay frozen (kStay) or carry that load alone (kHoldLoad,
    // force only: write_contacts). kHoldLoad bounds the sum of the rows'
    // magnitudes by the limit as well, so no load the device could not
    // render reaches the tissue in any form: rows that push sideways can
    // still squeeze the tissue under a small resultant (its pinned solve
    // leaves out only the rows facing against the held push,
    // held_load_facing; docs/design/force-aware-decision.md).
    const double held_load =
        held == HeldProxy::kHoldLoad ? std::max(load, tissue_magnitudes()) : load;
    if (held_load > device.renderable_force_n) {
      tissue_force_scale_ = device.renderable_force_n / held_load;
      report_.tissue_force_scaled_held = true;
    }
    // kHoldLoad: held, the tissue carries the load alone; catching up, it
    // does once the load had to be scaled.
    report_.tissue_held_by_load =
        held == HeldProxy::kHoldLoad &&
        (state_ == TrackingState::kLostTrack || report_.tissue_force_scaled_held);
  } else if (load > kWedgeBand * device.renderable_force_n) {
    tissue_force_scale_ = device.renderable_force_n / load;
    report_.tissue_force_clamped = true;
  }
  return solved_reaction;
}

double ContactResponse::tissue_load(double resultant_norm) const {
  if (body_count_ < 2) return resultant_norm;
  double load = 0.0;
  for (std::size_t b = 0; b < body_count_; ++b) {
    const std::uint32_t end =
        b + 1 < body_count_ ? body_first_ids_[b + 1] : std::numeric_limits<std::uint32_t>::max();
    load += solver_.resultant(RowKind::kTissue, body_first_ids_[b], end).norm();
  }
  return load;
}

double ContactResponse::tissue_magnitudes() const {
  double sum = 0.0;
  for (std::size_t i = 0; i < solver_.size(); ++i) {
    if (solver_.row(i).kind == RowKind::kTissue) sum += solver_.lambda(i);
  }
  return sum;
}

void ContactResponse::set_tissue_bodies(std::span<const std::uint32_t> first_ids) {
  if (first_ids.size() > kMaxTissueBodies) {
    throw std::invalid_argument("ContactResponse::set_tissue_bodies: more than " +
                                std::to_string(kMaxTissueBodies) + " bodies");
  }
  if (!first_ids.empty() && first_ids.front() != 0) {
    throw std::invalid_argument(
        "ContactResponse::set_tissue_bodies: the first body's first id "
        "must be 0");
  }
  for (std::size_t b = 1; b < first_ids.size(); ++b) {
    if (first_ids[b] <= first_ids[b - 1]) {
      throw std::invalid_argument("ContactResponse::set_tissue_bodies: first ids must ascend");
    }
  }
  std::copy(first_ids.begin(), first_ids.end(), body_first_ids_.begin());
  body_count_ = std::max<std::size_t>(first_ids.size(), 1);
}

const ForceOutput& ContactResponse::tick(const TickInput& input) {
  const DeviceSample& device = input.device;
  report_ = TickReport{};
  solver_.reset_work();
  const Eigen::Vector3d p0 = proxy_.position_m;
  const EffectiveCoupling coupling =
      effective_coupling(settings_.coupling, device.max_stiffness_npm, device.dt_s,
                         device.position_m, device.velocity_mps, p0);
  using Clock = std::chrono::steady_clock;
  using Micro = std::chrono::duration<double, std::micro>;
  const auto start = Clock::now();
  report_.load = solver_.load(input.rows, input.compliance);
  if (settings_.mode == ResponseMode::kNaive) solver_.make_rigid();
  const auto loaded = Clock::now();
  const Eigen::Vector3d step = keep_out_of_bone(move_proxy(input, coupling));
  const auto moved = Clock::now();
  solver_.store_warm_start();
  report_.pgs = solver_.last_report();
  report_.state = state_;

  proxy_.position_m = p0 + step;
  proxy_.orientation = device.orientation;
  proxy_.velocity_mps = step / device.dt_s;
  fill_output(device, coupling);
  const double solved_reaction = scale_tissue_forces(device);
  output_.tissue_reaction_n = tissue_force_scale_ * solved_reaction;
  report_.obstacle_reaction_n = solver_.resultant(RowKind::kObstacle).norm();
  output_.active_contacts = 0;
  for (std::size_t i = 0; i < solver_.size(); ++i)
    output_.active_contacts += solver_.lambda(i) > 0.0 ? 1u : 0u;
  output_.fem_step = input.compliance.fem_step;
  report_.pgs_work = solver_.work();
  previous_reaction_n_ = solved_reaction;

  // The FEM sees the tool where the proxy is; the naive loop's tool is the
  // device itself (it has no tissue model to stop it).
  const Eigen::Vector3d plane_shift =
      settings_.mode == ResponseMode::kNaive ? Eigen::Vector3d(device.position_m - p0) : step;
  write_contacts(input, plane_shift);
  report_.load_us = Micro(loaded - start).count();
  report_.move_us = Micro(moved - loaded).count();
  report_.output_us = Micro(Clock::now() - moved).count();
  return output_;
}

}  // namespace fahr::contact
