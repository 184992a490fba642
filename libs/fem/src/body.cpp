// The per-step pipeline of one body: forces, system, solve, projection, sleep.
#include "fahr/fem/body.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "fahr/fem/compression_stiffening.h"
#include "fahr/fem/corotation.h"
#include "fahr/fem/hyperelastic_element.h"
#include "fahr/fem/lumped_mass.h"
#include "fahr/geometry/tet_deformation.h"

namespace fahr::fem {

namespace {

// FactorInstall::kWhenDone: a background factorisation this many latencies
// past its own is waited for (the factor in use lags by at most one more).
constexpr std::uint64_t kOverdueLatencies = 10;

std::string validate(const SolverSettings& solver) {
  if (solver.refactor_period < 0) return "solver settings: refactor_period must be >= 0";
  if (solver.cg_max_iterations < 0) return "solver settings: cg_max_iterations must be >= 0";
  if (!(solver.cg_relative_tolerance >= 0.0))
    return "solver settings: cg_relative_tolerance must be >= 0";
  if (!(solver.refactor_rotation_rad >= 0.0))
    return "solver settings: refactor_rotation_rad must be >= 0";
  if (solver.cg_refresh_iterations < 0)
    return "solver settings: cg_refresh_iterations must be >= 0";
  if (!(solver.refactor_stiffening_change >= 0.0)) {
    return "solver settings: refactor_stiffening_change must be >= 0";
  }
  if (!(solver.refactor_deformation_change >= 0.0)) {
    return "solver settings: refactor_deformation_change must be >= 0";
  }
  if (!(solver.tangent_reuse_change >= 0.0)) {
    return "solver settings: tangent_reuse_change must be >= 0";
  }
  if (!(solver.background_factor_latency_s >= 0.0) ||
      !std::isfinite(solver.background_factor_latency_s)) {
    return "solver settings: background_factor_latency_s must be finite and >= 0";
  }
  return {};
}

}  // namespace

BodyOrError Body::create(const BodySettings& settings,
                         std::span<const Eigen::Vector3d> rest_positions_m,
                         std::span<const Tet> tets, std::span<const std::uint32_t> fixed_nodes) {
  BodyOrError result;
  const std::string material_error = validate(settings.material);
  if (!material_error.empty()) {
    result.error = material_error;
    return result;
  }
  if (!(settings.time_step.count() > 0.0) || !std::isfinite(settings.time_step.count())) {
    result.error = "time_step must be finite and > 0";
    return result;
  }
  const std::string solver_error = validate(settings.solver);
  if (!solver_error.empty()) {
    result.error = solver_error;
    return result;
  }
  if (!settings.gravity_m_per_s2.allFinite()) {
    result.error = "gravity_m_per_s2 must be finite";
    return result;
  }
  std::unique_ptr<Body> body(new Body());
  body->settings_ = settings;
  result.error = body->initialise(rest_positions_m, tets, fixed_nodes);
  if (result.error.empty()) result.body = std::move(body);
  return result;
}

std::string Body::initialise(std::span<const Eigen::Vector3d> rest_positions_m,
                             std::span<const Tet> tets,
                             std::span<const std::uint32_t> fixed_nodes) {
  if (rest_positions_m.empty() || tets.empty()) return "mesh has no nodes or no tets";
  std::string error = build_element_rest(rest_positions_m, tets, rest_);
  if (!error.empty()) return error;
  const std::size_t n = rest_positions_m.size();
  const auto dofs = static_cast<Eigen::Index>(3 * n);
  h_ = settings_.time_step.count();
  lame_ = lame_parameters(settings_.material);
  mass_kg_ = lumped_mass(rest_, n, settings_.material.density_kg_per_m3);
  inverse_mass_.assign(n, 0.0);
  fixed_dof_.assign(3 * n, 0);
  for (const std::uint32_t node : fixed_nodes) {
    if (node >= n) return "fixed node " + std::to_string(node) + " out of range";
    for (std::size_t d = 0; d < 3; ++d) fixed_dof_[3 * std::size_t{node} + d] = 1;
  }
  total_mass_kg_ = 0.0;
  for (const double m : mass_kg_) total_mass_kg_ += m;
  const double mean_mass = total_mass_kg_ / static_cast<double>(n);
  mass_per_dof_.assign(3 * n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    // A node in no tet has no mass and no stiffness: it is held fixed, and
    // its decoupled row gets a representative mass for conditioning.
    if (!(mass_kg_[i] > 0.0)) {
      for (std::size_t d = 0; d < 3; ++d) fixed_dof_[3 * i + d] = 1;
    }
    if (fixed_dof_[3 * i] == 0) inverse_mass_[i] = 1.0 / mass_kg_[i];
    for (std::size_t d = 0; d < 3; ++d)
      mass_per_dof_[3 * i + d] = mass_kg_[i] > 0.0 ? mass_kg_[i] : mean_mass;
  }
  rest_x_.resize(dofs);
  for (std::size_t i = 0; i < n; ++i)
    rest_x_.segment<3>(3 * static_cast<Eigen::Index>(i)) = rest_positions_m[i];
  x_ = rest_x_;
  v_.setZero(dofs);
  x_start_.setZero(dofs);
  force_.setZero(dofs);
  external_force_.setZero(dofs);
  rhs_.setZero(dofs);
  v_next_.setZero(dofs);
  x_trial_.setZero(dofs);
  gravity_force_.setZero(dofs);
  for (std::size_t i = 0; i < n; ++i) {
    gravity_force_.segment<3>(3 * static_cast<Eigen::Index>(i)) =
        mass_kg_[i] * settings_.gravity_m_per_s2;
  }
  supports_.assign(n, NodeSupport{});
  held_at_factor_.assign(n, 0);
  factor_held_.assign(n, 0);
  tet_supports_.assign(rest_.size(), TetSupport{});
  tet_held_at_factor_.assign(rest_.size(), 0);
  factor_held_tets_.assign(rest_.size(), 0);
  rotations_.assign(rest_.size(), Eigen::Matrix3d::Identity());
  rotations_at_factor_ = rotations_;
  if (settings_.material.model == MaterialModel::kStableNeoHookean) {
    // The Yeoh ratio is the energy's term here, not a secant scale.
    snh_.emplace(settings_.material);
    deformations_.assign(rest_.size(), Eigen::Matrix3d::Identity());
    deformations_at_factor_ = deformations_;
    // No element has a tangent yet: NaN never compares within reach.
    tangent_deformations_.assign(
        rest_.size(), Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN()));
    element_tangents_.assign(rest_.size(), Matrix12d::Zero());
  }
  stiffening_ = !snh_ && settings_.material.yeoh_c20_over_c10 > 0.0;
  if (stiffening_) {
    stiffening_scales_.assign(rest_.size(), 1.0);
    stiffening_scales_at_factor_ = stiffening_scales_;
  }
  assembly_.build(n, rest_, fixed_dof_);
  cg_.resize(3 * n);
  compliance_.reserve(3 * n, settings_.max_compliance_spheres);
  warp_.resize(n);
  warp_.set_enabled(settings_.solver.warp_lagged_factor);
  if (!cholmod_.analyze(assembly_.matrix(), settings_.solver.cholmod))
    return "CHOLMOD symbolic analysis failed";
  compliance_.reserve_panels(cholmod_);
  assemble_system();
  if (!refactorise()) return "the rest system matrix is not positive definite";
  return configure_background_factor();
}

std::string Body::configure_background_factor() {
  const SolverSettings& solver = settings_.solver;
  factor_latency_steps_ = 0;
  if (!(solver.background_factor_latency_s > 0.0) || solver.refactor_period == 1) return {};
  if (!cholmod_.enable_background()) return "CHOLMOD background factorisation failed to start";
  // The job's copies (set-up: these allocate).
  job_assembly_ = assembly_;
  job_deformations_.assign(deformations_.size(), Eigen::Matrix3d::Zero());
  job_rotations_.assign(rotations_.size(), Eigen::Matrix3d::Identity());
  job_scales_.assign(stiffening_scales_.size(), 1.0);
  job_supports_.assign(supports_.size(), NodeSupport{});
  job_support_count_ = 0;
  job_tet_supports_.assign(tet_supports_.size(), TetSupport{});
  job_tet_support_count_ = 0;
  factor_latency_steps_ = static_cast<std::uint64_t>(
      std::max(1.0, std::ceil(solver.background_factor_latency_s / h_ - 1e-9)));
  return {};
}

Body::~Body() {
  cholmod_.cancel_factorize();
}

void Body::cancel_background_factor() {
  cholmod_.cancel_factorize();
  compliance_.drop_refresh();
  factor_pending_ = false;
  factor_late_ = false;
  steps_late_ = 0;
}

void Body::assemble_system() {
  assemble_into(assembly_, deformations_, rotations_, stiffening_scales_,
                {supports_.data(), support_count_}, {tet_supports_.data(), tet_support_count_},
                support_ratio_);
}

void Body::assemble_job(void* body, std::span<double> values) {
  Body& b = *static_cast<Body*>(body);
  b.assemble_into(b.job_assembly_, b.job_deformations_, b.job_rotations_, b.job_scales_,
                  {b.job_supports_.data(), b.job_support_count_},
                  {b.job_tet_supports_.data(), b.job_tet_support_count_}, b.job_support_ratio_);
  const SparseMatrix& a = b.job_assembly_.matrix();
  std::copy(a.valuePtr(), a.valuePtr() + a.nonZeros(), values.begin());
}

void Body::refresh_job(void* body, CholmodSolver::NewFactor& new_factor) {
  static_cast<Body*>(body)->compliance_.refresh_on(new_factor);
}

void Body::assemble_into(SystemAssembly& out, std::span<const Eigen::Matrix3d> deformations,
                         std::span<const Eigen::Matrix3d> rotations, std::span<const double> scales,
                         std::span<const NodeSupport> supports,
                         std::span<const TetSupport> tet_supports, double support_ratio) {
  const double alpha = settings_.material.rayleigh_mass_per_s;
  const double beta = settings_.material.rayleigh_stiffness_s;
  if (snh_) {
    // The tangent at the start of the step: each element's Hessian at its
    // F, projected to positive semi-definite (its analytic eigensystem), so
    // A is positive definite however compressed or inverted the element.
    // An element whose F has moved less than tangent_reuse_change since its
    // tangent was computed keeps that tangent (a lag far below the refresh
    // trigger's); the others are computed again.
    out.zero();
    const double stiffness_scale = h_ * beta + h_ * h_;
    const double reuse = settings_.solver.tangent_reuse_change;
    const double reuse_squared = reuse * reuse;
    for (std::size_t e = 0; e < rest_.size(); ++e) {
      const Eigen::Matrix3d& f = deformations[e];
      if (!((f - tangent_deformations_[e]).squaredNorm() <= reuse_squared) || !(reuse > 0.0)) {
        element_tangents_[e] = element_stiffness(shape_gradients(rest_.dm_inv[e]),
                                                 rest_.volume_m3[e], snh_->projected_hessian(f));
        tangent_deformations_[e] = f;
      }
      out.add_element(e, element_tangents_[e], stiffness_scale);
    }
    out.add_mass(mass_per_dof_, 1.0 + h_ * alpha);
  } else {
    out.assemble(rest_, rotations, lame_, mass_per_dof_, 1.0 + h_ * alpha, h_ * beta + h_ * h_,
                 scales);
  }
  out.add_supports(supports, tet_supports, support_ratio);
}

void Body::assemble_current(SystemAssembly& out) const {
  const double alpha = settings_.material.rayleigh_mass_per_s;
  const double beta = settings_.material.rayleigh_stiffness_s;
  const double stiffness_scale = h_ * beta + h_ * h_;
  if (snh_) {
    out.zero();
    for (std::size_t e = 0; e < rest_.size(); ++e) {
      const Eigen::Matrix3d f =
          geometry::deformation_gradient(x_.data(), rest_.tets[e], rest_.dm_inv[e]);
      out.add_element(e,
                      element_stiffness(shape_gradients(rest_.dm_inv[e]), rest_.volume_m3[e],
                                        snh_->projected_hessian(f)),
                      stiffness_scale);
    }
    out.add_mass(mass_per_dof_, 1.0 + h_ * alpha);
  } else {
    std::vector<Eigen::Matrix3d> rotations(rest_.size());
    std::vector<double> scales(stiffening_ ? rest_.size() : 0, 1.0);
    for (std::size_t e = 0; e < rest_.size(); ++e) {
      const Eigen::Matrix3d f =
          geometry::deformation_gradient(x_.data(), rest_.tets[e], rest_.dm_inv[e]);
      rotations[e] = rotation_from_deformation(f).rotation;
      if (stiffening_) scales[e] = stiffening_scale(f, settings_.material.yeoh_c20_over_c10);
    }
    out.assemble(rest_, rotations, lame_, mass_per_dof_, 1.0 + h_ * alpha, stiffness_scale, scales);
  }
  out.add_supports({supports_.data(), support_count_}, {tet_supports_.data(), tet_support_count_},
                   support_ratio_);
}

void Body::set_supports(std::span<const NodeSupport> supports,
                        std::span<const TetSupport> tet_supports, double stiffness_ratio) {
  support_count_ = 0;
  tet_support_count_ = 0;
  support_ratio_ = stiffness_ratio > 0.0 ? stiffness_ratio : 0.0;
  std::size_t held_then = 0;  // of the new sets, nodes and tets the factorisation holds too
  if (support_ratio_ > 0.0) {
    for (const NodeSupport& s : supports) {
      if (s.node >= node_count() || fixed(s.node) || !s.normal.allFinite() ||
          support_count_ == supports_.size()) {
        continue;
      }
      supports_[support_count_++] = s;
      held_then += held_at_factor_[s.node];
    }
    for (const TetSupport& s : tet_supports) {
      bool finite = true;
      for (const Eigen::Vector3d& part : s.direction) finite = finite && part.allFinite();
      if (s.tet >= rest_.size() || !finite || tet_support_count_ == tet_supports_.size()) continue;
      tet_supports_[tet_support_count_++] = s;
      held_then += tet_held_at_factor_[s.tet];
    }
  }
  // Nodes and tets held now and not in the factorisation, and the other way
  // round.
  const std::size_t held_now = support_count_ + tet_support_count_;
  support_changes_ = (held_now - held_then) + (held_at_factor_count_ - held_then);
}

std::string Body::set_solver(const SolverSettings& solver) {
  std::string error = validate(solver);
  if (!error.empty()) return error;
  const bool reanalyse = solver.cholmod.factor != settings_.solver.cholmod.factor ||
                         solver.cholmod.ordering != settings_.solver.cholmod.ordering;
  cancel_background_factor();
  settings_.solver = solver;
  warp_.set_enabled(solver.warp_lagged_factor);
  if (reanalyse && !cholmod_.analyze(assembly_.matrix(), solver.cholmod))
    return "CHOLMOD symbolic analysis failed";
  if (reanalyse) compliance_.reserve_panels(cholmod_);
  warp_.update_rotations(rest_, rotations_);
  if (snh_) update_deformations();
  assemble_system();
  if (!refactorise()) return "the system matrix is not positive definite";
  return configure_background_factor();
}

bool Body::refactorise() {
  mark_factor_state();
  return cholmod_.factorize();
}

void Body::mark_factor_state() {
  steps_since_factor_ = 0;
  refresh_due_ = false;
  for (std::size_t i = 0; i < held_at_factor_count_ - factor_held_tet_count_; ++i)
    held_at_factor_[factor_held_[i]] = 0;
  for (std::size_t i = 0; i < factor_held_tet_count_; ++i)
    tet_held_at_factor_[factor_held_tets_[i]] = 0;
  held_at_factor_count_ = support_count_ + tet_support_count_;
  for (std::size_t i = 0; i < support_count_; ++i) {
    factor_held_[i] = supports_[i].node;
    held_at_factor_[supports_[i].node] = 1;
  }
  factor_held_tet_count_ = tet_support_count_;
  for (std::size_t i = 0; i < tet_support_count_; ++i) {
    factor_held_tets_[i] = tet_supports_[i].tet;
    tet_held_at_factor_[tet_supports_[i].tet] = 1;
  }
  support_changes_ = 0;
  std::copy(rotations_.begin(), rotations_.end(), rotations_at_factor_.begin());
  std::copy(stiffening_scales_.begin(), stiffening_scales_.end(),
            stiffening_scales_at_factor_.begin());
  std::copy(deformations_.begin(), deformations_.end(), deformations_at_factor_.begin());
  warp_.mark_factorised();
}

int Body::update_rotations_and_forces(bool accumulate_energy, double* elastic_energy_j) {
  int inverted = 0;
  const double* x = x_.data();
  double* f = force_.data();
  for (std::size_t e = 0; e < rest_.size(); ++e) {
    const Tet& tet = rest_.tets[e];
    const Eigen::Matrix3d deformation = geometry::deformation_gradient(x, tet, rest_.dm_inv[e]);
    const Corotation corotation = rotation_from_deformation(deformation);
    inverted += corotation.inverted ? 1 : 0;
    const Eigen::Matrix3d& r = corotation.rotation;
    rotations_[e] = r;
    // The stiffened element acts as s times as much of the linear material
    // (compression_stiffening.h); s = 1 exactly without stiffening.
    double scale = 1.0;
    if (stiffening_) {
      scale = stiffening_scale(deformation, settings_.material.yeoh_c20_over_c10);
      stiffening_scales_[e] = scale;
    }
    // Small strain in the rotated frame, linear stress, rotated back:
    // f = -s R K0 (R^T x - X) written per element as -s V P Dm^-T.
    const Eigen::Matrix3d unrotated = r.transpose() * deformation;
    const Eigen::Matrix3d strain =
        0.5 * (unrotated + unrotated.transpose()) - Eigen::Matrix3d::Identity();
    const double trace = strain.trace();
    Eigen::Matrix3d stress = 2.0 * lame_.mu_pa * strain;
    stress.diagonal().array() += lame_.lambda_pa * trace;
    const double volume = scale * rest_.volume_m3[e];
    const Eigen::Matrix3d h = -volume * (r * stress) * rest_.dm_inv[e].transpose();
    Eigen::Map<Eigen::Vector3d>(f + 3 * std::size_t{tet[0]}) -= h.col(0) + h.col(1) + h.col(2);
    for (Eigen::Index a = 0; a < 3; ++a) {
      Eigen::Map<Eigen::Vector3d>(f + 3 * std::size_t{tet[static_cast<std::size_t>(a + 1)]}) +=
          h.col(a);
    }
    if (accumulate_energy) {
      *elastic_energy_j +=
          volume * (lame_.mu_pa * strain.squaredNorm() + 0.5 * lame_.lambda_pa * trace * trace);
    }
  }
  return inverted;
}

int Body::update_hyperelastic_forces(bool accumulate_energy, double* elastic_energy_j) {
  int inverted = 0;
  const double* x = x_.data();
  double* f = force_.data();
  for (std::size_t e = 0; e < rest_.size(); ++e) {
    const Tet& tet = rest_.tets[e];
    const Eigen::Matrix3d deformation = geometry::deformation_gradient(x, tet, rest_.dm_inv[e]);
    deformations_[e] = deformation;
    inverted += deformation.determinant() > 0.0 ? 0 : 1;
    // f = -V P Dm^-T for nodes 1..3 (node 0 takes minus their sum): the
    // exact -d(V Psi)/dx, hyperelastic_element.h's nodal_forces without the
    // 9x12 matrix.
    const double volume = rest_.volume_m3[e];
    const Eigen::Matrix3d h =
        -volume * snh_->first_piola(deformation) * rest_.dm_inv[e].transpose();
    Eigen::Map<Eigen::Vector3d>(f + 3 * std::size_t{tet[0]}) -= h.col(0) + h.col(1) + h.col(2);
    for (Eigen::Index a = 0; a < 3; ++a) {
      Eigen::Map<Eigen::Vector3d>(f + 3 * std::size_t{tet[static_cast<std::size_t>(a + 1)]}) +=
          h.col(a);
    }
    if (accumulate_energy) *elastic_energy_j += volume * snh_->energy_density(deformation);
  }
  return inverted;
}

void Body::update_deformations() {
  for (std::size_t e = 0; e < rest_.size(); ++e) {
    deformations_[e] = geometry::deformation_gradient(x_.data(), rest_.tets[e], rest_.dm_inv[e]);
  }
}

int Body::update_elastic_forces(bool accumulate_energy, double* elastic_energy_j) {
  return snh_ ? update_hyperelastic_forces(accumulate_energy, elastic_energy_j)
              : update_rotations_and_forces(accumulate_energy, elastic_energy_j);
}

bool Body::deformed_since_factor() const {
  const double change = settings_.solver.refactor_deformation_change;
  if (!snh_ || !(change > 0.0)) return false;
  const double limit = change * change;
  for (std::size_t e = 0; e < deformations_.size(); ++e) {
    if ((deformations_[e] - deformations_at_factor_[e]).squaredNorm() > limit) return true;
  }
  return false;
}

// The support springs changed A: the direct solve refactorises when the
// rotation trigger is on (a factor without them would not feel the bone at
// all). CG multiplies with the current A, but W comes from the factor:
// without the springs in it W was off by up to 95 % on the pressed tongue
// (fem_tongue_press), so a lagged-factor CG refreshes too. A few nodes
// joining or leaving the held set are a small low-rank change of A, and
// nodes sitting on the bone with no force flicker in and out from step to
// step: refreshing on every change refactorised in most pressed steps, and
// each refresh solves W's columns again. So the
// factor follows the held set once a quarter of it (and at least
// kSupportChangesForRefresh nodes) changed.
bool Body::support_changed_factor_due(bool cg) const {
  const bool many = support_changes_ >= kSupportChangesForRefresh &&
                    4 * support_changes_ >= held_at_factor_count_;
  return many && (cg || settings_.solver.refactor_rotation_rad > 0.0);
}

bool Body::rotated_since_factor() const {
  const double threshold = settings_.solver.refactor_rotation_rad;
  if (!(threshold > 0.0)) return false;
  // The angle of R_now R_then^T exceeds the threshold iff its trace,
  // sum_ij R_now(i,j) R_then(i,j), is below 1 + 2 cos(threshold).
  const double min_trace = 1.0 + 2.0 * std::cos(threshold);
  for (std::size_t e = 0; e < rotations_.size(); ++e) {
    if (rotations_[e].cwiseProduct(rotations_at_factor_[e]).sum() < min_trace) return true;
  }
  return false;
}

bool Body::stiffened_since_factor() const {
  const double change = settings_.solver.refactor_stiffening_change;
  if (!stiffening_ || !(change > 0.0)) return false;
  for (std::size_t e = 0; e < stiffening_scales_.size(); ++e) {
    const double then = stiffening_scales_at_factor_[e];
    if (std::abs(stiffening_scales_[e] - then) > change * then) return true;
  }
  return false;
}

bool Body::accept_contacts(const ContactSet* contacts, const SphereLinks* links,
                           StepReport& report) {
  if (contacts == nullptr || links == nullptr || contacts->contacts.empty()) return false;
  if (links->node_bound() > node_count()) {
    // Links built for another mesh: using them would index past the arrays.
    ++invalid_sets_;
    report.contacts_invalid = true;
    return false;
  }
  // A set from the future cannot refer to a state this body has produced.
  // The age counts from the later of the state it answers and its arrival
  // (ContactSet::received_step).
  const std::uint64_t since = std::max(contacts->state_step, contacts->received_step);
  if (contacts->state_step > step_ || since > step_ ||
      step_ - since > settings_.max_contact_age_steps) {
    ++stale_sets_;
    report.contacts_stale = true;
    return false;
  }
  return true;
}

double Body::kinetic_energy() const {
  double energy = 0.0;
  for (std::size_t i = 0; i < mass_kg_.size(); ++i) {
    energy += 0.5 * mass_kg_[i] * v_.segment<3>(3 * static_cast<Eigen::Index>(i)).squaredNorm();
  }
  return energy;
}

void Body::finish_step(StepReport& report) {
  ++step_;
  report.step = step_;
  report.time_s = static_cast<double>(step_) * h_;
}

double Body::compute_forces(StepReport& report) {
  force_ = gravity_force_ + external_force_;
  double elastic_energy_j = 0.0;
  report.inverted_elements = update_elastic_forces(snh_.has_value(), &elastic_energy_j);
  double residual_squared = 0.0;
  for (Eigen::Index k = 0; k < force_.size(); ++k) {
    if (fixed_dof_[static_cast<std::size_t>(k)] == 0) residual_squared += force_[k] * force_[k];
  }
  report.residual_force_n = std::sqrt(residual_squared);
  return elastic_energy_j;
}

double Body::elastic_energy_at(const double* y) const {
  double energy = 0.0;
  for (std::size_t e = 0; e < rest_.size(); ++e) {
    const Eigen::Matrix3d f = geometry::deformation_gradient(y, rest_.tets[e], rest_.dm_inv[e]);
    energy += rest_.volume_m3[e] * snh_->energy_density(f);
  }
  return energy;
}

// The linearised implicit step is one Newton step, from x, on the step's
// incremental potential
//   E(y) = |y - x - h v|^2_M / (2 h^2) + sum V Psi(F(y)) - f_ext . y
// (backward Euler as a minimisation; Rayleigh damping's quadratic is left
// out, its gradient at y = x is zero), along d = h v' with v' = A^-1 (M v +
// h f). A is positive definite, so d descends: dE/dt at t = 0 is -v'.(M v +
// h f) = -v'^T A v' < 0. A lagged A (the factor from several steps back, or
// a tangent assembled before the tissue stiffened) is softer than the
// current tangent and the full step can overshoot the minimum so far that
// E rises; repeated, the step amplifies itself until the body diverges.
// Armijo backtracking keeps every step downhill: halve t until E(x + t d)
// <= E(x) + c t dE/dt. With the full step accepted (every step of the
// shipped intubation) nothing changes, bit for bit.
void Body::search_line(double elastic_energy_j, StepReport& report) {
  constexpr double kArmijo = 1e-4;
  constexpr int kMaxHalvings = 10;
  const auto dofs = static_cast<std::size_t>(x_.size());
  double slope = 0.0;  // dE/dt at t = 0, J
  double scale = std::abs(elastic_energy_j);
  for (std::size_t k = 0; k < dofs; ++k) {
    if (fixed_dof_[k] != 0) continue;
    const auto i = static_cast<Eigen::Index>(k);
    slope -= rhs_[i] * v_next_[i];
    scale += std::abs(mass_per_dof_[k] * v_[i] * v_[i]) +
             std::abs((gravity_force_[i] + external_force_[i]) * x_[i]);
  }
  // Differences of sums this large are exact to a few ulps of `scale`.
  const double noise = 64.0 * std::numeric_limits<double>::epsilon() * scale;
  // At rest, or a descent too small for the energy to resolve: nothing to
  // check (the change would be rounding, not overshoot).
  if (!(-slope > noise)) return;
  double t = 1.0;
  for (int halving = 0; halving <= kMaxHalvings; ++halving) {
    // E(x + t d) - E(x), d = h v': the inertia, external and elastic parts.
    double change = 0.0;
    for (std::size_t k = 0; k < dofs; ++k) {
      const auto i = static_cast<Eigen::Index>(k);
      const double step = fixed_dof_[k] != 0 ? 0.0 : t * h_ * v_next_[i];
      x_trial_[i] = x_[i] + step;
      if (step == 0.0) continue;
      // (|s - h v|^2 - |h v|^2) m / (2 h^2) = m s (s - 2 h v) / (2 h^2)
      change += 0.5 * mass_per_dof_[k] * step * (step - 2.0 * h_ * v_[i]) / (h_ * h_) -
                (gravity_force_[i] + external_force_[i]) * step;
    }
    change += elastic_energy_at(x_trial_.data()) - elastic_energy_j;
    if (change <= kArmijo * t * slope + noise) break;  // NaN goes on halving
    if (halving == kMaxHalvings) {
      report.line_search_exhausted = true;  // the shortest step, reported
      break;
    }
    t *= 0.5;
    report.line_search_halvings = halving + 1;
  }
  if (t < 1.0) v_next_ *= t;
}

void Body::prepare_system(StepReport& report) {
  const SolverSettings& solver = settings_.solver;
  const bool cg = solver.kind == LinearSolver::kConjugateGradient;
  const bool factor_needed = !cg || solver.preconditioner == CgPreconditioner::kLaggedCholesky;
  // The background factorisation begun factor_latency_steps_ ago (or
  // longer): waited for if not done, so its step does not depend on the
  // thread's speed, or, in real time, taken at the first step that finds it
  // done, and waited for once kOverdueLatencies latencies' worth of steps
  // have gone on without it (the factor in use lags by at most that).
  bool install = false;
  if (factor_pending_ && step_ >= factor_install_step_) {
    const bool done = cholmod_.background_done();
    if (!done && !factor_late_) {
      factor_late_ = true;
      ++late_factorisations_;
    }
    const bool overdue = steps_late_ >= kOverdueLatencies * factor_latency_steps_;
    install = done || overdue || solver.factor_install == FactorInstall::kWait;
    if (!install) ++steps_late_;  // this step goes on with the factor before
    if (install && !done && solver.factor_install == FactorInstall::kWhenDone) ++overdue_waits_;
  }
  if (install) {
    most_steps_late_ = std::max(most_steps_late_, steps_late_);
    steps_late_ = 0;
    factor_late_ = false;
    factor_pending_ = false;
    report.refactorised = cholmod_.finish_factorize();
    if (report.refactorised) {
      compliance_.adopt_refresh(cholmod_);
    } else {
      compliance_.drop_refresh();
    }
    // A failed one (A not positive definite) leaves the factor before; the
    // triggers then compare against the state it failed at, so ask again.
    refresh_due_ = refresh_due_ || !report.refactorised;
  }
  const bool factor_due =
      (solver.refactor_period > 0 && steps_since_factor_ + 1 >= solver.refactor_period) ||
      (factor_needed && refresh_due_) ||
      (factor_needed && solver.refactor_period != 1 &&
       (support_changed_factor_due(cg) || rotated_since_factor() || stiffened_since_factor() ||
        deformed_since_factor()));
  if (factor_needed) warp_.update_rotations(rest_, rotations_);
  // One background factorisation at a time: a trigger while one is under
  // way waits for it (the triggers then compare against its state).
  const bool begin = factor_due && factor_needed && !factor_pending_;
  // CG multiplies with the current A; the direct solve only needs A when it
  // refactorises, and in the background the job assembles it from a copy
  // of this step's state (the same A, off this thread).
  const bool job_assembles = begin && !cg && background_factor();
  if (cg || (begin && !job_assembles)) assemble_system();
  if (begin && background_factor()) {
    mark_factor_state();
    // The block's spheres of the last W, solved again on the new factor by
    // the factorisation's thread.
    const bool refresh = refresh_with_factor_ && compliance_links_ != nullptr &&
                         compliance_.begin_refresh(*compliance_links_, fixed_dof_) > 0;
    const CholmodSolver::AfterFactor after = refresh ? &Body::refresh_job : nullptr;
    if (job_assembles) {
      std::copy(deformations_.begin(), deformations_.end(), job_deformations_.begin());
      std::copy(rotations_.begin(), rotations_.end(), job_rotations_.begin());
      std::copy(stiffening_scales_.begin(), stiffening_scales_.end(), job_scales_.begin());
      std::copy_n(supports_.begin(), support_count_, job_supports_.begin());
      job_support_count_ = support_count_;
      std::copy_n(tet_supports_.begin(), tet_support_count_, job_tet_supports_.begin());
      job_tet_support_count_ = tet_support_count_;
      job_support_ratio_ = support_ratio_;
      factor_pending_ = cholmod_.begin_factorize(&Body::assemble_job, this, after);
    } else {
      factor_pending_ = cholmod_.begin_factorize(nullptr, this, after);
    }
    if (!factor_pending_) compliance_.drop_refresh();
    factor_install_step_ = step_ + factor_latency_steps_;
  } else if (begin) {
    report.refactorised = refactorise();
  } else {
    ++steps_since_factor_;
  }
}

void Body::solve_velocity(StepReport& report) {
  for (Eigen::Index k = 0; k < rhs_.size(); ++k) {
    const auto dof = static_cast<std::size_t>(k);
    rhs_[k] = fixed_dof_[dof] != 0 ? 0.0 : mass_per_dof_[dof] * v_[k] + h_ * force_[k];
  }
  const SolverSettings& solver = settings_.solver;
  const auto dofs = static_cast<std::size_t>(rhs_.size());
  if (solver.kind == LinearSolver::kConjugateGradient) {
    v_next_ = v_;  // warm start from the previous velocity
    const CgResult result =
        cg_.solve(assembly_.matrix(), assembly_.diagonal_index(), {rhs_.data(), dofs},
                  {v_next_.data(), dofs}, solver.cg_relative_tolerance, solver.cg_max_iterations,
                  solver.preconditioner, &cholmod_, &warp_);
    report.solver_iterations = result.iterations;
    report.solver_relative_residual = result.relative_residual;
    // The factor has drifted too far from A to precondition it cheaply.
    refresh_due_ = solver.preconditioner == CgPreconditioner::kLaggedCholesky &&
                   solver.cg_refresh_iterations > 0 &&
                   (result.iterations > solver.cg_refresh_iterations || !result.converged);
  } else {
    warp_.solve(cholmod_, rhs_.data(), v_next_.data());
  }
}

void Body::integrate_and_project(const ContactSet* contacts, const SphereLinks* links,
                                 StepReport& report) {
  x_start_ = x_;
  x_ += h_ * v_next_;
  if (contacts == nullptr) {
    v_ = v_next_;
    return;
  }
  report.contacts_applied = true;
  report.projection =
      project_contacts(*contacts, *links, inverse_mass_, settings_.projection,
                       {x_.data(), static_cast<std::size_t>(x_.size())},
                       {x_start_.data(), static_cast<std::size_t>(x_start_.size())});
  v_ = (x_ - x_start_) / h_;
}

StepReport Body::step(const ContactSet* contacts, const SphereLinks* links) {
  StepReport report;
  const bool use_contacts = accept_contacts(contacts, links, report);
  bool touching = external_force_set_;
  if (use_contacts) {
    for (const Contact& contact : contacts->contacts)
      touching = touching || contact_is_projected(contact);
  }
  if (sleep_.asleep() && touching) sleep_.wake();
  if (sleep_.asleep()) {
    report.asleep = true;
    finish_step(report);
    return report;
  }
  // 1. forces at x^n, 2. A as the solver settings ask, 3. A v' = M v + h f.
  std::int64_t t0 = thread_cpu_ns();
  const auto lap = [&t0](std::int64_t& part) {
    const std::int64_t t = thread_cpu_ns();
    part += t - t0;
    t0 = t;
  };
  const double elastic_energy_j = compute_forces(report);
  lap(report.cpu.forces_ns);
  prepare_system(report);
  lap(report.cpu.system_ns);
  solve_velocity(report);
  lap(report.cpu.solve_ns);
  if (snh_ && v_next_.allFinite()) search_line(elastic_energy_j, report);
  lap(report.cpu.line_search_ns);
  if (!v_next_.allFinite()) {
    // Guard against a broken factorisation or CG breakdown: keep the state,
    // stop the motion, and report; never publish NaN.
    report.solve_failed = true;
    v_.setZero();
    finish_step(report);
    return report;
  }
  // 4. x' = x + h v', Algorithm 1 projection, v = (x~ - x^n) / h.
  integrate_and_project(use_contacts ? contacts : nullptr, links, report);
  // 5. Sleep bookkeeping.
  report.kinetic_energy_j = kinetic_energy();
  const double weight = total_mass_kg_ * settings_.gravity_m_per_s2.norm();
  if (sleep_.update(settings_.sleep, report.kinetic_energy_j, total_mass_kg_,
                    report.residual_force_n, weight, touching)) {
    v_.setZero();
  }
  finish_step(report);
  return report;
}

bool Body::compliance(std::span<const std::uint32_t> spheres, const SphereLinks& links,
                      std::span<float> out) {
  if (!prepare_compliance_factor()) return false;
  compliance_links_ = &links;
  return compliance_.compute(spheres, links, fixed_dof_, cholmod_, warp_, h_, out);
}

bool Body::compliance_along(std::span<const std::uint32_t> spheres,
                            std::span<const Eigen::Vector3d> normals, const SphereLinks& links,
                            std::span<float> out) {
  if (!prepare_compliance_factor()) return false;
  return compliance_.compute_along(spheres, normals, links, fixed_dof_, cholmod_, warp_, h_, out);
}

bool Body::step_motion(std::span<const double> force_n, std::span<double> dx_m) {
  const std::size_t dofs = 3 * node_count();
  if (force_n.size() != dofs || dx_m.size() != dofs) return false;
  if (!prepare_compliance_factor() || !cholmod_.factorized()) return false;
  motion_rhs_.resize(dofs);
  motion_dofs_.resize(dofs);
  std::size_t loaded = 0;
  for (std::size_t i = 0; i < dofs; ++i) {
    motion_rhs_[i] = fixed_dof_[i] != 0 ? 0.0 : force_n[i];
    if (motion_rhs_[i] != 0.0) motion_dofs_[loaded++] = static_cast<std::uint32_t>(i);
  }
  // The contact forces act on a few hundred DOFs: the forward half of the
  // solve runs on the supernodes they reach only.
  if (!warp_.enabled() && cholmod_.sparse_forward_ready()) {
    cholmod_.solve_sparse({motion_dofs_.data(), loaded}, motion_rhs_, dx_m);
  } else {
    warp_.solve(cholmod_, motion_rhs_.data(), dx_m.data());
  }
  const double h2 = h_ * h_;
  for (std::size_t i = 0; i < dofs; ++i) dx_m[i] = fixed_dof_[i] != 0 ? 0.0 : h2 * dx_m[i];
  return true;
}

bool Body::prepare_compliance_factor() {
  const SolverSettings& solver = settings_.solver;
  const bool factor_unused = solver.kind == LinearSolver::kConjugateGradient &&
                             solver.preconditioner == CgPreconditioner::kJacobi;
  if (factor_unused && solver.refactor_period > 0 &&
      steps_since_factor_ >= solver.refactor_period) {
    // Jacobi-CG keeps no factorisation per step; A of the last step is
    // assembled, so refresh the factor from it when it is older than asked.
    warp_.update_rotations(rest_, rotations_);
    if (!refactorise()) return false;
  }
  if (factor_unused) warp_.update_rotations(rest_, rotations_);
  return true;
}

void Body::set_external_force(std::uint32_t node, const Eigen::Vector3d& force_n) {
  external_force_.segment<3>(3 * Eigen::Index{node}) = force_n;
  if (force_n.squaredNorm() > 0.0) {
    external_force_set_ = true;
    sleep_.wake();
  }
}

void Body::clear_external_forces() {
  external_force_.setZero();
  external_force_set_ = false;
}

void Body::set_node_position(std::uint32_t node, const Eigen::Vector3d& position_m) {
  x_.segment<3>(3 * Eigen::Index{node}) = position_m;
  sleep_.wake();
}

void Body::wake() {
  sleep_.wake();
}

bool Body::reset_to_rest() {
  cancel_background_factor();
  x_ = rest_x_;
  v_.setZero();
  clear_external_forces();
  sleep_.wake();
  support_count_ = 0;
  tet_support_count_ = 0;
  std::fill(rotations_.begin(), rotations_.end(), Eigen::Matrix3d::Identity());
  std::fill(stiffening_scales_.begin(), stiffening_scales_.end(), 1.0);
  std::fill(deformations_.begin(), deformations_.end(), Eigen::Matrix3d::Identity());
  // Every tangent computed again, so the body steps exactly as a new one.
  std::fill(tangent_deformations_.begin(), tangent_deformations_.end(),
            Eigen::Matrix3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  warp_.update_rotations(rest_, rotations_);
  assemble_system();
  return refactorise();
}

void Body::elastic_forces(std::span<double> out_n) {
  force_.setZero();
  update_elastic_forces(false, nullptr);
  std::copy(force_.data(), force_.data() + force_.size(), out_n.begin());
}

Energy Body::energy() {
  Energy energy;
  force_.setZero();
  update_elastic_forces(true, &energy.elastic_j);
  energy.kinetic_j = kinetic_energy();
  energy.gravity_potential_j = -gravity_force_.dot(x_);
  return energy;
}

}  // namespace fahr::fem
