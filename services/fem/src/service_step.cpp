// One FEM service step: wire ContactSet in, DeformationState out.
#include "fahr/fem_service/service_step.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>

#include "fahr/common/clock.h"
#include "fahr/common/packed_symmetric.h"
#include "fahr/fem_service/contact_conversion.h"

namespace fahr::fem_service {
namespace {

// Twice the rest body's box diagonal: no deformation moves a node that far,
// a diverged step does (ContactStepSettings::divergence_limit_m).
double divergence_limit_m(const geometry::TetMesh& mesh) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3d& x : mesh.rest_positions()) box.extend(x);
  return box.isEmpty() ? 0.0 : 2.0 * box.diagonal().norm();
}

}  // namespace

ServiceStep::ServiceStep(FemBodySetup& setup)
    : setup_(setup),
      contact_step_(
          *setup.body, setup.links,
          fem::ContactStepSettings{.apply_contact_forces = true,
                                   .max_compliance_spheres = setup.settings.max_compliance_spheres,
                                   .compliance_along_normals = setup.compliance_along_normals,
                                   .divergence_limit_m = divergence_limit_m(setup.mesh),
                                   .volume_floor = setup.volume_floor}),
      layout_check_(setup.layout_fingerprint),
      max_age_ns_(
          static_cast<std::int64_t>(static_cast<double>(setup.settings.max_contact_age_steps) *
                                    setup.body->time_step_s() * 1e9)) {
  const std::size_t cap = setup.settings.max_compliance_spheres;
  std::vector<const fem::ObstacleField*> anatomy;
  if (setup.enforce_anatomy) {
    for (const auto& field : setup.anatomy) anatomy.push_back(field.get());
  }
  contact_step_.set_obstacles(anatomy, setup.anatomy_settings);
  contacts_.contacts.reserve(msg::MAX_CONTACTS);
  state_.positions_m().reserve(3 * setup.mesh.node_count());
  state_.velocities_mps().reserve(3 * setup.mesh.node_count());
  state_.compliance_sphere_ids().reserve(cap);
  state_.compliance_mpn().reserve(9 * cap * cap);
  state_.compliance_free_centres_m().reserve(3 * cap);
  state_.compliance_normals().reserve(3 * cap);
}

namespace {

std::int64_t body_clock_ns(const fem::Body& body) {
  return static_cast<std::int64_t>(static_cast<double>(body.step_index()) * body.time_step_s() *
                                   1e9);
}

}  // namespace

void ServiceStep::take(const msg::ContactSet& wire, std::uint64_t seq, std::int64_t received_ns) {
  if (!all_finite(wire)) {
    // Never used, nor the set before it (which it supersedes).
    non_finite_sets_.fetch_add(1, std::memory_order_relaxed);
    have_contacts_ = false;
    return;
  }
  const std::size_t spheres = setup_.links.size();
  if (std::any_of(wire.contacts().begin(), wire.contacts().end(),
                  [&](const msg::Contact& c) { return c.sphere_id() >= spheres; })) {
    unknown_sphere_sets_.fetch_add(1, std::memory_order_relaxed);
    have_contacts_ = false;
    return;
  }
  if (wire.fem_step() > setup_.body->step_index()) {
    // It answers a state this body has not produced: one of an FEM service
    // before a restart (its steps numbered further). Never applied; the
    // haptic service's next set answers this body's states.
    ahead_sets_.fetch_add(1, std::memory_order_relaxed);
    have_contacts_ = false;
    return;
  }
  if (!layout_check_.accept(wire.layout_fingerprint())) {
    // Its sphere ids name other spheres: nothing of it is applied, nor the
    // set before it (which it supersedes).
    have_contacts_ = false;
    return;
  }
  to_fem(wire, contacts_);
  received_ns_ = received_ns == kBodyClock ? body_clock_ns(*setup_.body) : received_ns;
  have_contacts_ = true;
  applied_contact_seq_ = seq;
}

void ServiceStep::step(std::int64_t now_ns) {
  // A set computed on the tongue before a reset is ignored and counted
  // (stale): applied to the rested tongue, a blade placed for the diverged
  // one pushed its nodes tens of millimetres in one step, and the next step
  // flung them. So is the last set of a haptic service that went silent:
  // none newer for the maximum age since it arrived, on the caller's clock
  // (wall time in real time: a FEM catching up runs steps back to back, and
  // a count of steps would call a live sender silent). A set that answers an
  // older state but is the newest sent is applied: its planes are where the
  // tool is, and ignoring it would take the tool off the tongue and empty
  // the compliance block whenever the haptic side's snapshot lagged behind.
  const std::int64_t now = now_ns == kBodyClock ? body_clock_ns(*setup_.body) : now_ns;
  const bool usable =
      have_contacts_ && contacts_.state_step >= reset_step_ && now - received_ns_ <= max_age_ns_;
  // The body judges a set by steps (fem::ContactSet::received_step): this
  // one is current at this step.
  if (usable) contacts_.received_step = setup_.body->step_index();
  if (have_contacts_ && !usable) {
    ++stale_sets_;
    ++stale_run_;
  } else if (usable) {
    stale_followed_ += stale_run_;
    stale_run_ = 0;
  }
  const std::int64_t start_ns = common::monotonic_now_ns();
  const std::uint64_t solves_before = contact_step_.compliance_solves();
  last_report_ = contact_step_.step(usable ? &contacts_ : nullptr);
  const std::int64_t wall_ns = common::monotonic_now_ns() - start_ns;
  if (wall_ns > slowest_.wall_ns) {
    slowest_ = {.wall_ns = wall_ns,
                .step = setup_.body->step_index(),
                .refactorised = last_report_.refactorised,
                .compliance_solved = contact_step_.compliance_solves() != solves_before,
                .tool_contacts = usable ? contacts_.contacts.size() : 0,
                .projection_sweeps = last_report_.projection.sweeps,
                .anatomy_rounds = last_report_.projection.obstacle_rounds,
                .anatomy_nodes = last_report_.projection.obstacle_nodes,
                .inverted_elements = last_report_.inverted_elements};
  }
  inverted_max_ = std::max<std::uint64_t>(
      inverted_max_, static_cast<std::uint64_t>(last_report_.inverted_elements));
  if (last_report_.diverged_reset) {
    ++divergence_resets_;
    reset_step_ = setup_.body->step_index();
    resets_.fetch_add(1, std::memory_order_relaxed);
  }
  if (last_report_.line_search_halvings > 0) ++shortened_steps_;
  if (last_report_.line_search_exhausted) uphill_steps_.fetch_add(1, std::memory_order_relaxed);
  if (last_report_.solve_failed) failed_solves_.fetch_add(1, std::memory_order_relaxed);
  if (last_report_.refactorised) ++refactorisations_;
  anatomy_returned_ += static_cast<std::uint64_t>(last_report_.projection.obstacle_returned);
  anatomy_beyond_steps_ += static_cast<std::uint64_t>(last_report_.projection.obstacle_beyond);
  anatomy_depth_max_m_ = std::max(anatomy_depth_max_m_, last_report_.projection.obstacle_deepest_m);
  fill_state(*setup_.body, setup_.scene_body->id, state_);
  state_.stale_contact_sets(static_cast<std::uint32_t>(stale_sets_));
  state_.reset_epoch(static_cast<std::uint32_t>(divergence_resets_));
  state_.applied_contact_seq(usable ? applied_contact_seq_ : 0);
  fill_compliance();
}

void ServiceStep::fill_compliance() {
  const auto ids = contact_step_.compliance_spheres();
  const auto w = contact_step_.compliance();
  const auto free = contact_step_.free_centres();
  state_.compliance_sphere_ids().assign(ids.begin(), ids.end());
  const auto normals = contact_step_.compliance_normals();
  if (normals.empty()) {
    // 3k x 3k and symmetric (W = h^2 J A^-1 J^T): its upper triangle.
    const std::size_t n = 3 * ids.size();
    state_.compliance_mpn().resize(common::packed_upper_size(n));
    common::pack_upper(w.data(), n, state_.compliance_mpn().data());
  } else {
    state_.compliance_mpn().assign(w.begin(), w.end());
  }
  auto& along = state_.compliance_normals();
  along.resize(3 * normals.size());
  for (std::size_t s = 0; s < normals.size(); ++s) {
    for (std::size_t d = 0; d < 3; ++d)
      along[3 * s + d] = static_cast<float>(normals[s][static_cast<Eigen::Index>(d)]);
  }
  auto& centres = state_.compliance_free_centres_m();
  centres.resize(3 * free.size());
  for (std::size_t s = 0; s < free.size(); ++s) {
    for (std::size_t d = 0; d < 3; ++d)
      centres[3 * s + d] = static_cast<float>(free[s][static_cast<Eigen::Index>(d)]);
  }
}

void ServiceStep::take_errors(std::vector<std::string>& errors) {
  if (std::string error = layout_check_.take_error(); !error.empty())
    errors.push_back(std::move(error));
  const auto say = [&](const std::atomic<std::uint64_t>& count, std::uint64_t& said,
                       const char* what) {
    const std::uint64_t now = count.load(std::memory_order_relaxed);
    if (now == said) return;
    char text[200];
    std::snprintf(text, sizeof(text), "%s (%llu since the last report, %llu since start)", what,
                  static_cast<unsigned long long>(now - said),
                  static_cast<unsigned long long>(now));
    said = now;
    errors.emplace_back(text);
  };
  say(non_finite_sets_, non_finite_said_,
      "ContactSet refused: a non-finite number in a contact or the tool's pose; its contacts "
      "are not applied");
  say(ahead_sets_, ahead_said_,
      "ContactSet refused: it answers an FEM step this service has not reached (a state of an "
      "FEM service before a restart)");
  say(unknown_sphere_sets_, unknown_said_,
      "ContactSet refused: it names a sphere this body's layout does not have");
  say(failed_solves_, failed_said_,
      "FEM linear solve failed or gave a non-finite velocity: the step kept the positions with "
      "zero velocity");
  say(uphill_steps_, uphill_said_,
      "FEM step: the line search found no downhill step in 10 halvings (the factor far from "
      "the tissue's tangent); the shortest was taken");
  say(resets_, resets_said_,
      "FEM body diverged (a node non-finite or farther from rest than twice the body's size) "
      "and was reset to rest");
}

void ServiceStep::metrics(std::vector<std::pair<std::string, double>>& out) const {
  out.emplace_back("stale_contact_sets", static_cast<double>(stale_sets_));
  out.emplace_back("stale_contact_sets_followed", static_cast<double>(stale_followed_));
  out.emplace_back("layout_refused_sets", static_cast<double>(layout_check_.refused()));
  out.emplace_back("non_finite_contact_sets", static_cast<double>(non_finite_sets()));
  out.emplace_back("ahead_contact_sets", static_cast<double>(ahead_sets()));
  out.emplace_back("unknown_sphere_sets", static_cast<double>(unknown_sphere_sets()));
  common::append_admission_metrics(*contact_admission_, "contact_sets", out);
  out.emplace_back("failed_solves", static_cast<double>(failed_solves()));
  out.emplace_back("compliance_reuses", static_cast<double>(contact_step_.compliance_reuses()));
  out.emplace_back("inverted_elements_max", static_cast<double>(inverted_max_));
  out.emplace_back("divergence_resets", static_cast<double>(divergence_resets_));
  out.emplace_back("line_search_shortened_steps", static_cast<double>(shortened_steps_));
  out.emplace_back("line_search_uphill_steps", static_cast<double>(uphill_steps()));
  out.emplace_back("projection_sweeps_last", static_cast<double>(last_report_.projection.sweeps));
  out.emplace_back("anatomy_nodes_last",
                   static_cast<double>(last_report_.projection.obstacle_nodes));
  out.emplace_back("anatomy_depth_mm_max", 1e3 * anatomy_depth_max_m_);
  out.emplace_back("anatomy_nodes_returned", static_cast<double>(anatomy_returned_));
  out.emplace_back("anatomy_node_steps_beyond", static_cast<double>(anatomy_beyond_steps_));
  out.emplace_back("anatomy_unresolved_last",
                   static_cast<double>(last_report_.projection.obstacle_unresolved));
  out.emplace_back("volume_floor_below_last",
                   static_cast<double>(last_report_.projection.volume_floor_below));
  out.emplace_back("volume_floor_unresolved_last",
                   static_cast<double>(last_report_.projection.volume_floor_unresolved));
  out.emplace_back("solver_iterations_last", static_cast<double>(last_report_.solver_iterations));
  out.emplace_back("asleep", setup_.body->asleep() ? 1.0 : 0.0);
  out.emplace_back("nodes", static_cast<double>(setup_.mesh.node_count()));
  out.emplace_back("tets", static_cast<double>(setup_.mesh.tet_count()));
  out.emplace_back("spheres", static_cast<double>(setup_.links.size()));
}

std::int64_t ServiceStep::take_background_cpu_ns() {
  const std::int64_t now = setup_.body->background_cpu_ns();
  const std::int64_t used = now - background_cpu_taken_ns_;
  background_cpu_taken_ns_ = now;
  return used;
}

}  // namespace fahr::fem_service
