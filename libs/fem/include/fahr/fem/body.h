// One deformable body: tetrahedral FEM (corotational linear, or Stable
// Neo-Hookean hyperelastic: Material::model), one linearised implicit Euler
// step per call, then the Algorithm 1 projection of a ContactSet, and
// contact compliance on request.
//
// The step (with v the velocity, f the elastic force plus gravity and
// external forces, all at the start of the step, and K the stiffness there):
//   M (v' - v) = h (f - D v' - K h v'),   D = alpha M + beta K
//   =>  A v' = M v + h f,   A = (1 + h alpha) M + (h beta + h^2) K
//   x' = x + h v'
// which is one Newton step of backward Euler with f linearised about x
// (Baraff and Witkin 1998). Corotational: f is the corotated linear force
// and K = R K0 R^T (Mueller and Gross 2004); with compression stiffening each
// element's K0 is scaled by its s_e of the start of the step, in f and in A
// alike (compression_stiffening.h). Stable Neo-Hookean: f is the exact
// hyperelastic force -dE/dx (stable_neo_hookean.h) and K the tangent with
// each element's Hessian projected to positive semi-definite, so A stays
// positive definite through compression and inversion. The right-hand side
// needs no K, so a lagged A only changes the dynamics, never the static
// equilibrium; A is refactorised when it has really changed (solver_settings.h).
// Fixed DOFs are decoupled rows with v' = 0.
#pragma once

#include <Eigen/Core>
#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fahr/fem/assembly.h"
#include "fahr/fem/cg_solver.h"
#include "fahr/fem/cholmod_solver.h"
#include "fahr/fem/compliance.h"
#include "fahr/fem/contact_set.h"
#include "fahr/fem/element_rest.h"
#include "fahr/fem/hyperelastic_element.h"
#include "fahr/fem/material.h"
#include "fahr/fem/obstacle_support.h"
#include "fahr/fem/projection.h"
#include "fahr/fem/sleep.h"
#include "fahr/fem/solver_settings.h"
#include "fahr/fem/sphere_links.h"
#include "fahr/fem/stable_neo_hookean.h"
#include "fahr/fem/step_parts.h"
#include "fahr/fem/warped_factor.h"

namespace fahr::fem {

struct BodySettings {
  Material material = neonatal_tongue();
  std::chrono::duration<double> time_step{0.002};     // h, s, > 0
  Eigen::Vector3d gravity_m_per_s2{0.0, -9.81, 0.0};  // m/s^2, body frame
  SolverSettings solver;
  ProjectionSettings projection;
  SleepSettings sleep;
  // A ContactSet whose state_step and received_step are both more than
  // this many steps behind the body's step (or whose state_step is ahead of
  // it) is ignored and counted as stale.
  std::uint64_t max_contact_age_steps = 4;
  std::size_t max_compliance_spheres = 64;  // capacity of compliance()
};

struct StepReport {
  std::uint64_t step = 0;     // steps taken so far, this one included
  double time_s = 0.0;        // simulated time after the step, s
  bool asleep = false;        // no solve was done
  bool refactorised = false;  // a numeric factorisation happened this step
  bool solve_failed = false;  // non-finite or failed solve: state kept, v = 0
  int solver_iterations = 0;  // CG iterations (0 for a direct solve)
  double solver_relative_residual = 0.0;
  int inverted_elements = 0;  // det F <= 0 at the start of the step
  bool contacts_applied = false;
  bool contacts_stale = false;
  bool contacts_invalid = false;  // links reference nodes this body lacks
  // ContactStep: the step left a node non-finite or farther from rest than
  // ContactStepSettings::divergence_limit_m, so the body was reset to rest.
  bool diverged_reset = false;
  ProjectionReport projection;
  double kinetic_energy_j = 0.0;  // after the step, J
  double residual_force_n = 0.0;  // |f| over free DOFs at the start, N
  // Stable Neo-Hookean: halvings of the step the line search took (0: the
  // full linearised step lowered the step's potential enough).
  int line_search_halvings = 0;
  // ... and after all of them still uphill: the shortest step was taken (a
  // factor far from the tangent, or non-finite energy).
  bool line_search_exhausted = false;
  // The step thread's CPU per part (Body::step fills its parts,
  // ContactStep::step the rest).
  StepParts cpu;
};

struct Energy {
  double kinetic_j = 0.0;
  // Elastic energy, J. Stable Neo-Hookean: sum of V Psi(F), the energy the
  // force derives from. Corotational: the linear strain energy in each
  // rotated frame; with compression stiffening each element's s_e times it
  // (the scaled force derives from no energy, so this is the secant
  // estimate).
  double elastic_j = 0.0;
  double gravity_potential_j = 0.0;  // -m g . x summed, J (relative to origin)
  double total_j() const { return kinetic_j + elastic_j + gravity_potential_j; }
};

class Body;

struct BodyOrError {
  std::unique_ptr<Body> body;
  std::string error;  // empty on success
};

class Body {
 public:
  // Set-up: rest data, lumped mass, sparsity pattern, symbolic analysis and
  // the first factorisation. rest_positions_m: one per node, m. tets: four
  // node indices each, positive volume. fixed_nodes: never move.
  static BodyOrError create(const BodySettings& settings,
                            std::span<const Eigen::Vector3d> rest_positions_m,
                            std::span<const Tet> tets, std::span<const std::uint32_t> fixed_nodes);

  // Switches the linear solve (a comparison of solvers on one running body,
  // fem_bench's tongue_press): refactorises at the current state, analyses
  // again if the CHOLMOD options change. Returns an error naming the bad
  // setting (the body is then unchanged), or naming a failed analysis or
  // factorisation (the body then has no usable factor and must not be
  // stepped). Allocates: not for a per-step path.
  std::string set_solver(const SolverSettings& solver);

  // One step. `contacts` may be null (no set this step); `links` is needed
  // when contacts are given. No allocation after the first step, apart from
  // CHOLMOD's own (malloc) workspace on refactorisation steps.
  StepReport step(const ContactSet* contacts = nullptr, const SphereLinks* links = nullptr);

  // W = h^2 J A^-1 J^T for the listed spheres, (3k x 3k) row-major float,
  // m/N, from the solver's factorisation: exact when it was refactorised this
  // step (kCholmod with refactor_period 1), the lagged A otherwise.
  bool compliance(std::span<const std::uint32_t> spheres, const SphereLinks& links,
                  std::span<float> out);
  // Spheres of the block whose kept columns are solved again on a newer
  // factorisation per call (ComplianceBlock::set_refresh_per_call).
  void set_compliance_refresh(std::size_t spheres) { compliance_.set_refresh_per_call(spheres); }
  // Whether a background factorisation solves the block's spheres again on
  // its new factor, on its thread, so the install brings them along
  // (default; ComplianceBlock::begin_refresh). Off: only the budget above
  // refreshes them, on the step's thread (benches compare the two).
  void set_compliance_refresh_with_factor(bool on) { refresh_with_factor_ = on; }
  // Spheres' columns taken from the factorisation's thread so far.
  std::uint64_t compliance_refreshes_adopted() const { return compliance_.adopted_refreshes(); }
  // dx = h^2 A^-1 f on the factor W comes from: how the nodes move in one
  // step under the extra nodal force f (N, 3 per node); fixed DOFs neither
  // take force nor move. f and dx hold 3 * node_count() entries and may not
  // alias. False if the factor is missing. No allocation after the first call.
  bool step_motion(std::span<const double> force_n, std::span<double> dx_m);
  // The same W along one normal a sphere (ComplianceBlock::compute_along):
  // (3k x k), entry (3s + d, t) = (W_st n_t)_d.
  bool compliance_along(std::span<const std::uint32_t> spheres,
                        std::span<const Eigen::Vector3d> normals, const SphereLinks& links,
                        std::span<float> out);

  // Nodes the static anatomy holds and tets the volume floor holds
  // (obstacle_support.h): from the next step on, each gets a spring of
  // stiffness_ratio times its nodes' diagonal of A along its normal or
  // direction in A (and so in W). Replaces the previous sets; empty spans
  // remove them. A changed set makes a lagged factorisation due. Fixed nodes
  // are ignored. No allocation.
  void set_supports(std::span<const NodeSupport> supports, std::span<const TetSupport> tet_supports,
                    double stiffness_ratio);
  std::size_t support_count() const { return support_count_; }
  std::size_t tet_support_count() const { return tet_support_count_; }
  // Nodes and tets that joined or left the held sets since the
  // factorisation in use (its A holds the old sets' springs; audits of W
  // read it).
  std::size_t support_changes_since_factor() const { return support_changes_; }

  // External nodal force, N, held until changed; a non-zero force wakes.
  void set_external_force(std::uint32_t node, const Eigen::Vector3d& force_n);
  void clear_external_forces();
  // Teleports a node (a test's yank), m; velocity unchanged. Wakes the body.
  void set_node_position(std::uint32_t node, const Eigen::Vector3d& position_m);
  void wake();
  // Back to the state create() left: rest positions, no motion, no external
  // force, awake, the rest factorisation (refactorised, so a body that ran is
  // stepped exactly as a new one). The step count goes on, so ContactSets
  // keep their meaning. Not for a per-step path: the factorisation mallocs.
  bool reset_to_rest();

  // Elastic force of the current positions (the material model's), 3 per
  // node, N.
  void elastic_forces(std::span<double> out_n);
  Energy energy();

  std::size_t node_count() const { return mass_kg_.size(); }
  const ElementRest& element_rest() const { return rest_; }
  std::span<const double> positions_m() const {
    return {x_.data(), static_cast<std::size_t>(x_.size())};
  }
  std::span<const double> velocities_m_per_s() const {
    return {v_.data(), static_cast<std::size_t>(v_.size())};
  }
  Eigen::Vector3d position(std::uint32_t node) const {
    return x_.segment<3>(3 * Eigen::Index{node});
  }
  Eigen::Vector3d rest_position(std::uint32_t node) const {
    return rest_x_.segment<3>(3 * Eigen::Index{node});
  }
  std::span<const double> rest_positions_m() const {
    return {rest_x_.data(), static_cast<std::size_t>(rest_x_.size())};
  }
  std::span<const double> mass_kg() const { return mass_kg_; }
  std::span<const double> inverse_mass_per_kg() const { return inverse_mass_; }
  bool fixed(std::uint32_t node) const { return inverse_mass_[node] == 0.0; }
  bool asleep() const { return sleep_.asleep(); }
  std::uint64_t step_index() const { return step_; }
  std::uint64_t stale_sets_ignored() const { return stale_sets_; }
  std::uint64_t invalid_sets_ignored() const { return invalid_sets_; }
  double time_step_s() const { return h_; }
  double total_mass_kg() const { return total_mass_kg_; }
  const BodySettings& settings() const { return settings_; }
  bool hyperelastic() const { return snh_.has_value(); }
  const SparseMatrix& system_matrix() const { return assembly_.matrix(); }
  // A as the next step would linearise it, at the current positions with
  // every element's tangent (or rotation) computed afresh and the current
  // supports, written into `out` (built for this body: same node count,
  // rest data and fixed DOFs). For audits of a lagged factor and of W; the
  // body is not changed. Allocates (the corotational rotations).
  void assemble_current(SystemAssembly& out) const;
  // The fixed DOFs, one flag per DOF, as assembly and compliance take them.
  std::span<const std::uint8_t> fixed_dofs() const { return fixed_dof_; }
  double factor_nonzeros() const { return cholmod_.factor_nonzeros(); }
  // Whether CHOLMOD chose (or was told) a supernodal factor: compliance
  // blocks are then half solves (compliance.h).
  bool supernodal_factor() const { return cholmod_.supernodal(); }
  // Numeric factorisations so far, set-up included.
  std::uint64_t factorisations() const { return cholmod_.factorisations(); }
  // CPU time of the background factorisation thread so far, ns
  // (SolverSettings::background_factor_latency_s; 0 without it).
  std::int64_t background_cpu_ns() const { return cholmod_.background_cpu_ns(); }
  BackgroundCpu background_parts() const { return cholmod_.background_parts(); }
  // Background factorisations not done when their latency had passed: the
  // step waited for them (FactorInstall::kWait) or went on with the factor
  // before (kWhenDone). A machine too slow for the latency shows here.
  std::uint64_t late_factorisations() const { return late_factorisations_; }
  // With kWhenDone: the most steps that went on without one past its
  // latency (at most 10 latencies' worth: then the step waits), and how many
  // were waited for so.
  std::uint64_t most_steps_late() const { return most_steps_late_; }
  std::uint64_t overdue_waits() const { return overdue_waits_; }

  // Waits for a background factorisation under way: its thread writes into
  // the body's assembly copy and compliance block.
  ~Body();
  Body(const Body&) = delete;
  Body& operator=(const Body&) = delete;

 private:
  Body() = default;
  std::string initialise(std::span<const Eigen::Vector3d> rest_positions_m,
                         std::span<const Tet> tets, std::span<const std::uint32_t> fixed_nodes);
  // Rotations, elastic forces into force_ (accumulated), inverted count.
  int update_rotations_and_forces(bool accumulate_energy, double* elastic_energy_j);
  // The same for the hyperelastic material: deformation gradients, exact
  // forces into force_ (accumulated), inverted count (det F <= 0).
  int update_hyperelastic_forces(bool accumulate_energy, double* elastic_energy_j);
  // Deformation gradients of the current positions, nothing else.
  void update_deformations();
  // Elastic forces (and energy) of the current positions, either model.
  int update_elastic_forces(bool accumulate_energy, double* elastic_energy_j);
  // The stages of step().
  // Forces at x into force_; returns the elastic energy there (Stable
  // Neo-Hookean; 0 for the corotational model, which needs none).
  double compute_forces(StepReport& report);
  void prepare_system(StepReport& report);
  void solve_velocity(StepReport& report);
  // Stable Neo-Hookean: shortens v' until the step lowers its incremental
  // potential (Armijo backtracking); elastic_energy_j is sum V Psi at x.
  void search_line(double elastic_energy_j, StepReport& report);
  // Sum V Psi(F) at positions y (3 per node), J; the body is not changed.
  double elastic_energy_at(const double* y) const;
  void integrate_and_project(const ContactSet* contacts, const SphereLinks* links,
                             StepReport& report);
  void finish_step(StepReport& report);
  void assemble_system();
  // A from the given per-element state and supports into `out`; the
  // hyperelastic tangents kept in element_tangents_ are used and updated.
  void assemble_into(SystemAssembly& out, std::span<const Eigen::Matrix3d> deformations,
                     std::span<const Eigen::Matrix3d> rotations, std::span<const double> scales,
                     std::span<const NodeSupport> supports,
                     std::span<const TetSupport> tet_supports, double support_ratio);
  // The background factorisation's own assembly (CholmodSolver::FillValues):
  // A at the state copied when the job began, off the step's thread.
  static void assemble_job(void* body, std::span<double> values);
  // Then, on the same thread, the compliance block's spheres on the new
  // factor (CholmodSolver::AfterFactor).
  static void refresh_job(void* body, CholmodSolver::NewFactor& new_factor);
  bool refactorise();
  // What refactorise() records of the state A was assembled at (the
  // triggers compare against it), without the factorisation.
  void mark_factor_state();
  // Starts or installs background factorisations (prepare_system).
  bool background_factor() const { return factor_latency_steps_ > 0; }
  void cancel_background_factor();
  std::string configure_background_factor();
  // Brings the factor W is solved on up to date where the solver keeps none.
  bool prepare_compliance_factor();
  // True if an element rotated more than the setting since the factorisation.
  bool rotated_since_factor() const;
  // True if an element's stiffening scale changed by more than the setting.
  bool stiffened_since_factor() const;
  // True if an element's F changed by more than the setting (hyperelastic).
  bool deformed_since_factor() const;
  bool support_changed_factor_due(bool cg) const;
  bool accept_contacts(const ContactSet* contacts, const SphereLinks* links, StepReport& report);
  double kinetic_energy() const;

  BodySettings settings_;
  double h_ = 0.0;
  LameParameters lame_;
  ElementRest rest_;
  std::vector<double> mass_kg_;       // per node
  std::vector<double> inverse_mass_;  // per node, 0 when fixed
  std::vector<double> mass_per_dof_;  // per DOF, massless nodes get the mean
  std::vector<std::uint8_t> fixed_dof_;
  double total_mass_kg_ = 0.0;

  Eigen::VectorXd rest_x_, x_, v_, x_start_, force_, external_force_, gravity_force_, rhs_, v_next_,
      x_trial_;
  std::vector<Eigen::Matrix3d> rotations_;
  std::vector<Eigen::Matrix3d> rotations_at_factor_;
  // Compression stiffening (compression_stiffening.h), per element: the
  // scale at the start of the step and at the last factorisation. Empty
  // when the material has none.
  bool stiffening_ = false;
  std::vector<double> stiffening_scales_;
  std::vector<double> stiffening_scales_at_factor_;

  // Stable Neo-Hookean (Material::model): the material, and per element
  // F at the start of the step (the force's and the tangent's) and at the
  // last factorisation. Empty for the corotational model.
  std::optional<StableNeoHookean> snh_;
  std::vector<Eigen::Matrix3d> deformations_;
  std::vector<Eigen::Matrix3d> deformations_at_factor_;
  // Each element's tangent (its projected K_t block, N/m) and the F it was
  // computed at, kept between refreshes (SolverSettings::tangent_reuse_change).
  std::vector<Matrix12d> element_tangents_;
  std::vector<Eigen::Matrix3d> tangent_deformations_;

  SystemAssembly assembly_;
  // The background job's copies: its assembly (the same pattern), and the
  // state of the step that began it (the step goes on changing its own).
  // The job owns them, and element_tangents_, until it is installed or
  // cancelled. Used with the direct solve; CG assembles every step itself.
  SystemAssembly job_assembly_;
  std::vector<Eigen::Matrix3d> job_deformations_;
  std::vector<Eigen::Matrix3d> job_rotations_;
  std::vector<double> job_scales_;
  std::vector<NodeSupport> job_supports_;
  std::size_t job_support_count_ = 0;
  std::vector<TetSupport> job_tet_supports_;
  std::size_t job_tet_support_count_ = 0;
  double job_support_ratio_ = 0.0;
  CholmodSolver cholmod_;
  WarpedFactor warp_;
  CgSolver cg_;
  ComplianceBlock compliance_;
  std::vector<double> motion_rhs_;          // step_motion()'s right-hand side
  std::vector<std::uint32_t> motion_dofs_;  // ... its non-zero DOFs
  SleepMonitor sleep_;
  std::vector<NodeSupport> supports_;  // capacity: every node
  std::size_t support_count_ = 0;
  std::vector<TetSupport> tet_supports_;  // capacity: every tet
  std::size_t tet_support_count_ = 0;
  double support_ratio_ = 0.0;
  // The held sets in the last factorisation: a flag per node and per tet,
  // their nodes and tets, how many of both (held_at_factor_count_), and how
  // many joined or left them since (set_supports).
  std::vector<std::uint8_t> held_at_factor_;
  std::vector<std::uint32_t> factor_held_;
  std::vector<std::uint8_t> tet_held_at_factor_;
  std::vector<std::uint32_t> factor_held_tets_;
  std::size_t factor_held_tet_count_ = 0;
  std::size_t held_at_factor_count_ = 0;
  std::size_t support_changes_ = 0;
  static constexpr std::size_t kSupportChangesForRefresh = 8;
  int steps_since_factor_ = 0;
  // Background factorisation: steps from its start to its use (0: none),
  // whether one is under way, and the step it is installed at.
  std::uint64_t factor_latency_steps_ = 0;
  bool factor_pending_ = false;
  std::uint64_t factor_install_step_ = 0;
  bool factor_late_ = false;  // the pending one was not done at its latency
  bool refresh_with_factor_ = true;
  const SphereLinks* compliance_links_ = nullptr;  // of the last compliance()
  std::uint64_t late_factorisations_ = 0;
  std::uint64_t most_steps_late_ = 0;
  std::uint64_t overdue_waits_ = 0;
  std::uint64_t steps_late_ = 0;  // steps gone on without the pending factor
  // A CG solve took more than cg_refresh_iterations: refactorise next step.
  bool refresh_due_ = false;
  bool external_force_set_ = false;
  std::uint64_t step_ = 0;
  std::uint64_t stale_sets_ = 0;
  std::uint64_t invalid_sets_ = 0;
};

}  // namespace fahr::fem
