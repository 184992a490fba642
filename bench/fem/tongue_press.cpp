// fem_tongue_press: the FEM's linear solve on the neonatal tongue while the
// blade presses it, each candidate solver against the exact step (CHOLMOD
// refactorised every step, W exact), in the whole loop.
//
// Every configuration runs its own in-process lockstep stack
// (sim/stack_sim: gateway with the scripted hand, haptic service, FEM
// service) from the same scene, side by side, one base step each in turn,
// so all see the same hand and the same machine load at the same moment;
// the FEM's solver is switched after set-up (Body::set_solver). The loop is
// closed: a solver's error changes the contacts and the force (rendered
// force difference), and contact events are discontinuous, so closed-loop
// differences include their consequences and grow chaotically, not just
// one step's error. Each configuration therefore also has an open-loop
// shadow: a FEM service of its own fed the exact run's ContactSets, step for
// step, whose nodes and W are compared with the exact FEM's; the shadows
// also give each configuration's cost on identical inputs.
//
//   fem_tongue_press [--scene FILE] [--seconds 8] [--configs shipped,pcg-it8,...]
//                    [--script intubation|overshoot] [--support-ratio R]
//                    [--audit-from S] [--audit-to S] [--corrections] [--markdown [FILE]]
//
// --audit-from/--audit-to: W's audit only in that window of simulated time
// (a held state, e.g. the overshoot's hold at 3x, 5.5-10.5 s).
//
// Prints, per configuration: FEM step CPU (thread CPU, the step and its
// DeformationState) while the blade touches and over all steps, closed loop
// and shadow; refactorisations; CG iterations; the largest node
// displacement difference from the exact run (mm), closed loop and shadow;
// the largest relative difference of the shadow's W from the exact W; W's
// relative Frobenius error against a fresh factorisation of A linearised at
// the state the step solves from (W's error: the step's own system solved
// exactly) and at the state after it (what one step changes), for the
// leading 1, 8, 32 and 64 spheres, and the resultant of the tool's rows
// solved on each W (the same displacement asked of both; relative), and how
// much of the tool's load moves between spheres from one set to the next; the
// largest and RMS difference of the force sent to the device (N); the most
// inverted tets.
#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <memory>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "fahr/bench_support/results_file.h"
#include "fahr/cli/cli.h"
#include "fahr/common/clock.h"
#include "fahr/common/lockstep.h"
#include "fahr/common/solver_threads.h"
#include "fahr/common/wire_eigen.h"
#include "fahr/contact/pgs.h"
#include "fahr/contact/tissue_compliance.h"
#include "fahr/fem_service/fem_body_setup.h"
#include "fahr/fem_service/service_step.h"
#include "fahr/scene/load_scene.h"
#include "fahr/stack_sim/stack_sim.h"

namespace {

using fahr::fem::CgPreconditioner;
using fahr::fem::LinearSolver;
using fahr::fem::SolverSettings;

struct Config {
  std::string name;
  bool keep_scene_solver = false;  // "shipped": whatever the scene maps to
  std::size_t w_refresh = 0;       // "-wfresh": every column on each new factor (0: the FEM's)
  bool w_on_step_only = false;     // "-wstep": no refresh on the factorisation's thread
  SolverSettings solver;
};

// Names: exact, exact-amd, shipped, lagged (CHOLMOD, rotation trigger 0.1 rad),
// pcg-rot (CG, factor refreshed on the rotation trigger), pcg-rest (CG on
// the rest factor, never refreshed), pcg-itN (CG, refreshed when a solve
// took more than N iterations); a CG name may end in -warp (warped factor)
// and then -tolX (relative tolerance X instead of 1e-6), e.g.
// pcg-it12-tol1e-4. Any name may end in -wfresh: W's kept columns all solved
// again on each new factorisation instead of a budget a step; or in -wstep:
// W's kept columns refreshed only by the step's budget, not by the
// background factorisation's thread (how W was kept before that).
bool make_cg_config(const std::string& name, SolverSettings& s);

bool make_config(const std::string& full_name, Config& config) {
  config.name = full_name;
  std::string name = full_name;
  // "-wfresh": W's kept columns all solved again on each new factorisation.
  if (name.size() > 7 && name.substr(name.size() - 7) == "-wfresh") {
    config.w_refresh = 1024;
    name = name.substr(0, name.size() - 7);
  } else if (name.size() > 6 && name.substr(name.size() - 6) == "-wstep") {
    config.w_on_step_only = true;
    name = name.substr(0, name.size() - 6);
  }
  SolverSettings& s = config.solver;
  s.refactor_period = 0;
  s.refactor_rotation_rad = 0.0;
  if (name == "exact") {
    s.refactor_period = 1;
    return true;
  }
  if (name == "exact-amd") {
    // The exact step with another ordering: round-off-level differences
    // only, so its difference from "exact" is the closed loop's own
    // sensitivity, the floor under every other configuration's.
    s.refactor_period = 1;
    s.cholmod.ordering = fahr::fem::CholmodOrdering::kAmd;
    return true;
  }
  if (name == "shipped") {
    config.keep_scene_solver = true;
    return true;
  }
  if (name == "lagged") {
    s.refactor_rotation_rad = 0.1;
    return true;
  }
  s.kind = LinearSolver::kConjugateGradient;
  s.preconditioner = CgPreconditioner::kLaggedCholesky;
  s.cg_max_iterations = 200;
  std::string base = name;
  // "-tolX": CG relative tolerance X (default 1e-6).
  if (const auto tol = base.find("-tol"); tol != std::string::npos) {
    s.cg_relative_tolerance = std::atof(base.c_str() + tol + 4);
    if (!(s.cg_relative_tolerance > 0.0 && s.cg_relative_tolerance < 1.0)) return false;
    base = base.substr(0, tol);
  }
  // "-warp": the lagged factor rotated per node (warped_factor.h).
  if (base.size() > 5 && base.substr(base.size() - 5) == "-warp") {
    s.warp_lagged_factor = true;
    base = base.substr(0, base.size() - 5);
  }
  return make_cg_config(base, s);
}

bool make_cg_config(const std::string& name, SolverSettings& s) {
  if (name == "pcg-rot") {
    s.refactor_rotation_rad = 0.1;
    return true;
  }
  if (name == "pcg-rest") return true;
  if (name.rfind("pcg-it", 0) == 0) {
    s.cg_refresh_iterations = std::atoi(name.c_str() + 6);
    return s.cg_refresh_iterations > 0;
  }
  return false;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto i = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(i), v.end());
  return v[i];
}

// A FEM service of its own, fed the exact run's ContactSets.
struct Shadow {
  std::unique_ptr<fahr::fem_service::FemBodySetup> setup;
  std::unique_ptr<fahr::fem_service::ServiceStep> step;
  std::vector<double> cpu_touching_ms;
  std::vector<double> iterations;
  std::uint64_t factorisations_at_start = 0;
  double max_node_mm = 0.0;
  double max_w_relative =
      0.0;  // max |W - W_exact| / max |W_exact| over steps with the same spheres
  int max_inverted = 0;
  // W audit: W of a fresh factorisation of A linearised at the shadow's
  // own current state (every tangent afresh, the anatomy supports held),
  // the same spheres: how far the W the haptic loop solves on is from the
  // current linearised compliance.
  std::unique_ptr<fahr::fem::CholmodSolver> audit;
  fahr::fem::SystemAssembly audit_assembly;
  fahr::fem::ComplianceBlock audit_block;
  fahr::fem::WarpedFactor audit_warp;
  std::vector<float> audit_w;
  // Per audited step and leading sphere count (kAuditSpheres): relative
  // Frobenius error of the leading block.
  std::array<std::vector<double>, 5> audit_error;
  // The same against A linearised at the state the step began from (every
  // tangent afresh, the supports the step held): the system the step
  // solves, so W's own error; audit_error adds how far one step moves A.
  std::unique_ptr<fahr::fem::CholmodSolver> start_audit;
  fahr::fem::SystemAssembly start_assembly;
  fahr::fem::ComplianceBlock start_block;  // its own: a block keeps columns per factor count
  std::array<std::vector<double>, 5> start_error;
  // Per audited step, against the start state's A and against the state
  // after the step: the relative difference of the resultant of the tool's
  // rows solved on the fresh W from that solved on the W in use
  // (contact_forces).
  std::vector<double> start_force_error, audit_force_error;
  // The PGS's own floor: the resultant solved from zero on the W in use
  // against the haptic side's, relative.
  double force_floor_max = 0.0;
  std::size_t rows_outside_block = 0;  // tool rows whose sphere had no W slot
  // contact_forces' workspace.
  std::vector<std::size_t> row_slot;
  std::vector<Eigen::Vector3d> row_normal;
  std::vector<double> row_force, row_gap, lambda_used, lambda_fresh, pgs_residual, s_used, s_fresh;
  // The lagged factor's W corrected towards the start state's A (an
  // experiment, audit_corrections): every column solved on the factor in
  // use, then W1 = 2 J X - X^T A X with X = A_f^-1 J^T (first order in
  // A - A_f), and the same after one refinement of X.
  std::array<std::vector<double>, 5> lagged_error, first_order_error, refined_error;
  double correction_ms_max = 0.0;
  // Per corrections' audit, beside lagged_error[0] and first_order_error[0]:
  // the held set's changes since the factor.
  std::vector<std::size_t> support_changes;
  // Over the audited steps: the largest node motion in the step, mm, and
  // whether it went against the node's motion in the step before (a
  // state that only holds still, or one that rocks step to step).
  std::vector<double> step_motion_mm;
  std::size_t reversals = 0;
  std::vector<double> before_m;     // positions at the start of the step
  std::vector<double> step_m;       // each node's motion in this step
  std::vector<double> last_step_m;  // ... and in the step before
};

// A tool entry of a ContactSet that pushes the tissue (a row the haptic
// solve gave force, or a held load).
bool carries_tool_load(const fahr::msg::Contact& c) {
  const bool tool =
      c.kind() == fahr::msg::CONTACT_TOOL || c.kind() == fahr::msg::CONTACT_FORCE_ONLY;
  return tool && c.force_n() > 0.0;
}

// How much of the tool's load moves between spheres from one ContactSet to
// the next: sum over spheres of |lambda_now - lambda_before| over the
// larger of the two sets' sums (0: the same split; 2: no sphere shared).
struct LoadChurn {
  std::vector<double> before, now;  // per sphere id, N
  std::vector<std::uint32_t> touched_before, touched_now;
  double sum_before = 0.0;
  std::vector<double> shares;
  // Of the spheres carrying force in a set, the share that carried force in
  // the set before: whether the split moves within one set of rows or the
  // rows themselves change.
  std::vector<double> kept;
  void add(const fahr::msg::ContactSet& set) {
    double sum = 0.0;
    for (const fahr::msg::Contact& c : set.contacts()) {
      if (!carries_tool_load(c)) continue;
      if (c.sphere_id() >= now.size()) {
        now.resize(c.sphere_id() + 1, 0.0);
        before.resize(now.size(), 0.0);
      }
      if (now[c.sphere_id()] == 0.0) touched_now.push_back(c.sphere_id());
      now[c.sphere_id()] += c.force_n();
      sum += c.force_n();
    }
    const double larger = std::max(sum, sum_before);
    if (!touched_now.empty() && sum_before > 0.0) {
      std::size_t both = 0;
      for (const std::uint32_t sphere : touched_now) both += before[sphere] > 0.0 ? 1 : 0;
      kept.push_back(static_cast<double>(both) / static_cast<double>(touched_now.size()));
    }
    if (larger > 0.0 && sum_before > 0.0) {
      double moved = 0.0;
      for (const std::uint32_t s : touched_now) moved += std::abs(now[s] - before[s]);
      for (const std::uint32_t s : touched_before) {
        if (now[s] == 0.0) moved += before[s];
      }
      shares.push_back(moved / larger);
    }
    for (const std::uint32_t s : touched_before) before[s] = 0.0;
    for (const std::uint32_t s : touched_now) before[s] = now[s];
    for (const std::uint32_t s : touched_now) now[s] = 0.0;
    std::swap(touched_before, touched_now);
    touched_now.clear();
    sum_before = sum;
  }
};

// Leading spheres of the block whose W is audited (0: the whole block).
constexpr std::array<std::size_t, 5> kAuditSpheres{1, 8, 32, 64, 0};
// --corrections: the first-order corrections of W are audited as well.
bool g_corrections = false;

void start_audit(Shadow& shadow) {
  const fahr::fem::Body& body = *shadow.setup->body;
  shadow.audit_assembly.build(body.node_count(), body.element_rest(), body.fixed_dofs());
  shadow.audit = std::make_unique<fahr::fem::CholmodSolver>();
  shadow.audit->analyze(shadow.audit_assembly.matrix(), body.settings().solver.cholmod);
  shadow.start_assembly.build(body.node_count(), body.element_rest(), body.fixed_dofs());
  shadow.start_audit = std::make_unique<fahr::fem::CholmodSolver>();
  shadow.start_audit->analyze(shadow.start_assembly.matrix(), body.settings().solver.cholmod);
  shadow.audit_block.reserve(3 * body.node_count(), body.settings().max_compliance_spheres);
  // Every column solved again on each fresh factor.
  shadow.audit_block.set_refresh_per_call(body.settings().max_compliance_spheres);
  shadow.start_block.reserve(3 * body.node_count(), body.settings().max_compliance_spheres);
  shadow.start_block.set_refresh_per_call(body.settings().max_compliance_spheres);
  shadow.audit_warp.resize(body.node_count());
  shadow.audit_warp.set_enabled(false);
}

// Relative Frobenius error of each leading block of `used` against `fresh`
// (both 3k x 3k row-major), appended to `errors`.
template <typename Fresh, typename Used>
void leading_errors(std::size_t k, const Fresh& fresh, const Used& used,
                    std::array<std::vector<double>, 5>& errors) {
  const std::size_t rows = 3 * k;
  for (std::size_t a = 0; a < kAuditSpheres.size(); ++a) {
    const std::size_t lead = kAuditSpheres[a] == 0 ? k : kAuditSpheres[a];
    if (lead > k) continue;
    double diff = 0.0;
    double norm = 0.0;
    for (std::size_t i = 0; i < 3 * lead; ++i) {
      for (std::size_t j = 0; j < 3 * lead; ++j) {
        const double f = fresh(i * rows + j);
        const double u = used(i * rows + j);
        diff += (u - f) * (u - f);
        norm += f * f;
      }
    }
    if (norm > 0.0) errors[a].push_back(std::sqrt(diff / norm));
  }
}

// The forces the two W give the same rows. The rows are the tool's
// entries of the ContactSet the step took that carry a force, on spheres
// of the block, along their normals: S = N^T W N. The displacement the
// haptic side's forces make under the W in use, d = S_used lambda_h, is the
// right side of the tissue's LCP (S lambda >= d, lambda >= 0,
// complementary, pgs.h) solved on each W alike. The rows share spheres and
// overlap, so their split of a load is not unique; the resultant
// sum lambda_i n_i is what the hand feels, and its relative difference is
// appended to `errors`. The rows alone, without the tool's coupling beside
// W, are the stricter test: a coupling adds the same compliance to both.
void contact_forces(Shadow& shadow, const fahr::msg::ContactSet& fed,
                    std::span<const std::uint32_t> spheres, std::span<const float> w_used,
                    std::vector<double>& errors) {
  shadow.row_slot.clear();
  shadow.row_normal.clear();
  shadow.row_force.clear();
  for (const fahr::msg::Contact& c : fed.contacts()) {
    if (!carries_tool_load(c)) continue;
    const auto at = std::find(spheres.begin(), spheres.end(), c.sphere_id());
    if (at == spheres.end()) {
      ++shadow.rows_outside_block;
      continue;
    }
    shadow.row_slot.push_back(static_cast<std::size_t>(at - spheres.begin()));
    shadow.row_normal.push_back(fahr::common::to_eigen(c.normal()));
    shadow.row_force.push_back(c.force_n());
  }
  const std::size_t m = shadow.row_slot.size();
  if (m == 0) return;
  // n_i^T W_st n_j, as the tick builds its rows' matrix.
  const auto fill = [&](std::span<const float> w, std::vector<double>& s) {
    fahr::contact::TissueCompliance view;
    view.sphere_ids = spheres;
    view.w_mpn = w;
    s.assign(m * m, 0.0);
    for (std::size_t i = 0; i < m; ++i) {
      for (std::size_t j = 0; j < m; ++j) {
        s[i * m + j] = view.normal_compliance(shadow.row_slot[i], shadow.row_normal[i],
                                              shadow.row_slot[j], shadow.row_normal[j]);
      }
    }
  };
  fill(w_used, shadow.s_used);
  fill(shadow.audit_w, shadow.s_fresh);
  shadow.row_gap.assign(m, 0.0);
  for (std::size_t i = 0; i < m; ++i) {
    for (std::size_t j = 0; j < m; ++j) {
      shadow.row_gap[i] += shadow.s_used[i * m + j] * shadow.row_force[j];
    }
  }
  fahr::contact::PgsSettings settings;
  settings.max_sweeps = 20000;
  settings.tolerance_m = 1e-13;
  shadow.pgs_residual.resize(m);
  // Both from zero, so the W in use reproducing the haptic side's resultant
  // is the solver's own floor, not its starting point.
  const auto solve = [&](const std::vector<double>& s, std::vector<double>& lambda) {
    lambda.assign(m, 0.0);
    fahr::contact::solve_pgs(s.data(), m, m, shadow.row_gap.data(), lambda.data(),
                             shadow.pgs_residual.data(), settings);
  };
  solve(shadow.s_used, shadow.lambda_used);
  solve(shadow.s_fresh, shadow.lambda_fresh);
  Eigen::Vector3d haptic = Eigen::Vector3d::Zero();
  Eigen::Vector3d used = Eigen::Vector3d::Zero();
  Eigen::Vector3d fresh = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < m; ++i) {
    haptic += shadow.row_force[i] * shadow.row_normal[i];
    used += shadow.lambda_used[i] * shadow.row_normal[i];
    fresh += shadow.lambda_fresh[i] * shadow.row_normal[i];
  }
  if (haptic.norm() <= 0.0 || used.norm() <= 0.0) return;
  shadow.force_floor_max = std::max(shadow.force_floor_max, (used - haptic).norm() / haptic.norm());
  errors.push_back((fresh - used).norm() / used.norm());
}

// W of a fresh factorisation of the assembled A against the W in use:
// relative Frobenius error of each leading block, appended to `errors`, and
// the forces the two give the rows of `fed`, to `force_errors`.
void audit_against(Shadow& shadow, fahr::fem::CholmodSolver& fresh_factor,
                   fahr::fem::ComplianceBlock& block, std::array<std::vector<double>, 5>& errors,
                   const fahr::msg::ContactSet& fed, std::vector<double>& force_errors) {
  const auto& step = shadow.step->contact_step();
  const auto spheres = step.compliance_spheres();
  const auto w = step.compliance();
  const std::size_t k = spheres.size();
  const fahr::fem::Body& body = *shadow.setup->body;
  if (!fresh_factor.factorize()) return;
  shadow.audit_w.resize(w.size());
  if (!block.compute(spheres, shadow.setup->links, body.fixed_dofs(), fresh_factor,
                     shadow.audit_warp, body.time_step_s(), shadow.audit_w)) {
    return;
  }
  leading_errors(
      k, [&](std::size_t i) { return static_cast<double>(shadow.audit_w[i]); },
      [&](std::size_t i) { return static_cast<double>(w[i]); }, errors);
  contact_forces(shadow, fed, spheres, w, force_errors);
}

// The largest node motion of the step just made, and whether that node
// went back against its motion of the step before.
void record_step_motion(Shadow& shadow) {
  const auto x = shadow.setup->body->positions_m();
  shadow.step_m.resize(x.size());
  shadow.last_step_m.resize(x.size(), 0.0);
  for (std::size_t i = 0; i < x.size(); ++i) shadow.step_m[i] = x[i] - shadow.before_m[i];
  double largest2 = 0.0;
  std::size_t node = 0;
  for (std::size_t n = 0; 3 * n < x.size(); ++n) {
    const double moved2 = Eigen::Map<const Eigen::Vector3d>(&shadow.step_m[3 * n]).squaredNorm();
    if (moved2 > largest2) {
      largest2 = moved2;
      node = n;
    }
  }
  const Eigen::Map<const Eigen::Vector3d> now(&shadow.step_m[3 * node]);
  const Eigen::Map<const Eigen::Vector3d> before(&shadow.last_step_m[3 * node]);
  if (now.dot(before) < 0.0) ++shadow.reversals;
  shadow.step_motion_mm.push_back(1e3 * std::sqrt(largest2));
  std::swap(shadow.step_m, shadow.last_step_m);
}

// W = h^2 J A^-1 J^T corrected for the lag of the factor it is solved on
// (A_f, the factor in use) towards A, the start state's linearisation. With
// X = A_f^-1 J^T, W(X) = h^2 (2 J X - X^T A X) is stationary at the exact
// X = A^-1 J^T, so an X with error e gives W with error O(e^2): X from the
// lagged factor gives W to first order in A - A_f, and one refinement step
// X' = X + A_f^-1 (J^T - A X) to second. Compared with W from the same
// columns uncorrected (2 J X - X^T A_f X = J X). shadow.audit_w must hold
// the fresh W of the start state (audit_against with start_audit).
void audit_corrections(Shadow& shadow) {
  fahr::fem::Body& body = *shadow.setup->body;
  const auto spheres = shadow.step->contact_step().compliance_spheres();
  const std::size_t k = spheres.size();
  const std::size_t n = 3 * body.node_count();
  const std::size_t cols = 3 * k;
  const auto started = std::chrono::steady_clock::now();
  Eigen::MatrixXd f =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(cols));
  for (std::size_t s = 0; s < k; ++s) {
    const auto nodes = shadow.setup->links.nodes(spheres[s]);
    const auto weights = shadow.setup->links.weights(spheres[s]);
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      for (std::size_t d = 0; d < 3; ++d) {
        const auto row = static_cast<Eigen::Index>(3 * static_cast<std::size_t>(nodes[i]) + d);
        f(row, static_cast<Eigen::Index>(3 * s + d)) += weights[i];
      }
    }
  }
  const double h2 = body.time_step_s() * body.time_step_s();
  Eigen::MatrixXd dx(f.rows(), f.cols());  // h^2 X
  Eigen::VectorXd col(f.rows());
  const auto solve_columns = [&](const Eigen::MatrixXd& rhs, Eigen::MatrixXd& out) {
    for (Eigen::Index c = 0; c < rhs.cols(); ++c) {
      col = rhs.col(c);
      if (!body.step_motion({col.data(), n}, {out.col(c).data(), n})) return false;
    }
    return true;
  };
  if (!solve_columns(f, dx)) return;
  const fahr::fem::SparseMatrix& a = shadow.start_assembly.matrix();
  const Eigen::SparseMatrix<double> jt = f.sparseView();
  const auto corrected = [&](const Eigen::MatrixXd& x) {
    const Eigen::MatrixXd ax = a * x;
    Eigen::MatrixXd w = 2.0 * (jt.transpose() * x) - (x.transpose() * ax) / h2;
    return Eigen::MatrixXd(0.5 * (w + w.transpose()));
  };
  const Eigen::MatrixXd jdx = jt.transpose() * dx;
  const Eigen::MatrixXd lagged = 0.5 * (jdx + jdx.transpose());
  const Eigen::MatrixXd first = corrected(dx);
  // X' = X + A_f^-1 (J^T - A X): in dx's units, dx' = dx + step_motion(f - A dx / h^2).
  const Eigen::MatrixXd residual = f - (a * dx) / h2;
  Eigen::MatrixXd step(f.rows(), f.cols());
  if (!solve_columns(residual, step)) return;
  const Eigen::MatrixXd refined = corrected(dx + step);
  shadow.correction_ms_max =
      std::max(shadow.correction_ms_max,
               std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started)
                   .count());
  const auto fresh = [&](std::size_t i) { return static_cast<double>(shadow.audit_w[i]); };
  const auto entry = [&](const Eigen::MatrixXd& m) {
    // Row-major (3k x 3k) as W; m is symmetric, so the storage order is moot.
    return [&m, cols](std::size_t i) {
      return m(static_cast<Eigen::Index>(i / cols), static_cast<Eigen::Index>(i % cols));
    };
  };
  leading_errors(k, fresh, entry(lagged), shadow.lagged_error);
  leading_errors(k, fresh, entry(first), shadow.first_order_error);
  leading_errors(k, fresh, entry(refined), shadow.refined_error);
  // Kept in step with the one-sphere errors (a zero fresh W adds none).
  if (shadow.lagged_error[0].size() > shadow.support_changes.size()) {
    shadow.support_changes.push_back(body.support_changes_since_factor());
  }
}

// After the step; start_assembly holds A at the state it began from.
void audit_compliance(Shadow& shadow, const fahr::msg::ContactSet& fed) {
  record_step_motion(shadow);
  const auto& step = shadow.step->contact_step();
  const std::size_t k = step.compliance_spheres().size();
  if (k == 0 || step.compliance().size() != 9 * k * k) return;
  audit_against(shadow, *shadow.start_audit, shadow.start_block, shadow.start_error, fed,
                shadow.start_force_error);
  if (g_corrections) audit_corrections(shadow);
  shadow.setup->body->assemble_current(shadow.audit_assembly);
  audit_against(shadow, *shadow.audit, shadow.audit_block, shadow.audit_error, fed,
                shadow.audit_force_error);
}

struct Run {
  Config config;
  std::unique_ptr<fahr::stack_sim::StackSim> sim;
  Shadow shadow;
  fahr::msg::ContactSet fed;  // the ContactSet its FEM steps on in this base step
  std::uint64_t factorisations_at_start = 0;
  std::vector<double> cpu_touching_ms, cpu_all_ms;
  std::vector<double> iterations;
  double max_node_mm = 0.0;
  double max_force_n = 0.0;
  double force_sq_sum = 0.0;
  double peak_force_n = 0.0;
  std::uint64_t force_samples = 0;
  int max_inverted = 0;
};

// The ContactSet the FEM stepped on has a blade contact that pushes (not
// only candidates, not only the anatomy's entries).
bool blade_touches(const fahr::msg::ContactSet& set) {
  return std::any_of(set.contacts().begin(), set.contacts().end(), [](const fahr::msg::Contact& c) {
    return c.kind() == fahr::msg::CONTACT_FORCE_ONLY ||
           (c.kind() == fahr::msg::CONTACT_TOOL && c.state() != fahr::msg::CONSTRAINT_CANDIDATE);
  });
}

double force_norm(const fahr::msg::ForceCommand& c) {
  return fahr::common::to_eigen(c.force_n()).norm();
}

double force_difference(const fahr::msg::ForceCommand& a, const fahr::msg::ForceCommand& b) {
  return (fahr::common::to_eigen(a.force_n()) - fahr::common::to_eigen(b.force_n())).norm();
}

double largest_node_distance_mm(const fahr::fem::Body& a, const fahr::fem::Body& b) {
  const auto xa = a.positions_m();
  const auto xb = b.positions_m();
  double largest = 0.0;
  for (std::size_t i = 0; i + 2 < xa.size(); i += 3) {
    const double dx = xa[i] - xb[i];
    const double dy = xa[i + 1] - xb[i + 1];
    const double dz = xa[i + 2] - xb[i + 2];
    largest = std::max(largest, dx * dx + dy * dy + dz * dz);
  }
  return 1e3 * std::sqrt(largest);
}

// Largest entry difference over the largest exact entry, when both blocks
// are for the same spheres in the same order (else -1: not comparable).
double w_difference(const fahr::fem::ContactStep& exact, const fahr::fem::ContactStep& other) {
  const auto a = exact.compliance_spheres();
  const auto b = other.compliance_spheres();
  if (a.empty() || !std::equal(a.begin(), a.end(), b.begin(), b.end())) return -1.0;
  const auto wa = exact.compliance();
  const auto wb = other.compliance();
  if (wa.size() != wb.size()) return -1.0;
  double scale = 0.0;
  double largest = 0.0;
  for (std::size_t i = 0; i < wa.size(); ++i) {
    scale = std::max(scale, std::abs(double{wa[i]}));
    largest = std::max(largest, std::abs(double{wa[i]} - double{wb[i]}));
  }
  return scale > 0.0 ? largest / scale : 0.0;
}

std::string cell(double value, bool reference) {
  if (reference) return "(reference)";
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

// The pieces a step is made of, on the exact run's final A: what a
// refactorisation, one solve (one CG iteration's preconditioner), the full
// compliance block's solve and one product with A cost.
void print_kernel_costs(const fahr::fem::Body& body) {
  using fahr::common::thread_cpu_now_ns;
  const auto& a = body.system_matrix();
  fahr::fem::CholmodSolver factor;
  if (!factor.analyze(a) || !factor.factorize()) return;
  const auto n = static_cast<std::size_t>(a.rows());
  std::vector<double> b(48 * n, 1.0);
  std::vector<double> x(48 * n, 0.0);
  const auto time_ms = [](int repeats, auto&& work) {
    const std::int64_t start = thread_cpu_now_ns();
    for (int r = 0; r < repeats; ++r) work();
    return 1e-6 * static_cast<double>(thread_cpu_now_ns() - start) / repeats;
  };
  const double factorise_ms = time_ms(10, [&] { factor.factorize(); });
  const double solve_ms = time_ms(100, [&] { factor.solve({b.data(), n}, {x.data(), n}); });
  const double block_ms = time_ms(10, [&] { factor.solve_columns(b, x, 48); });
  const double product_ms =
      time_ms(100, [&] { fahr::fem::multiply_symmetric(a, b.data(), x.data()); });
  std::printf(
      "\nKernels on the final A (%zu DOFs, %.0f non-zeros in L, %s): factorisation %.2f ms, one "
      "solve "
      "%.3f ms, 48-column solve (16 spheres) %.2f ms, one product with A %.3f ms (thread CPU)\n",
      n, factor.factor_nonzeros(), factor.supernodal() ? "supernodal" : "simplicial", factorise_ms,
      solve_ms, block_ms, product_ms);
}

}  // namespace

// A function-try-block: what the set-up before the inner try throws ends in a message too.
int main(int argc, char** argv) try {
  fahr::common::run_solver_libraries_on_one_thread(argv);
  using namespace fahr;
  bench_support::MarkdownResults markdown(argc, argv);
  fahr::cli::App app{
      "FEM solvers on the pressed neonatal tongue against the exact step, in the whole loop"};
  app.footer(bench_support::kMarkdownHelp);
  std::string scene_path = FAHR_SOURCE_DIR "/deployment/scenes/neonatal_intubation.yaml";
  double seconds = 8.0;
  std::string config_list = "shipped,lagged,pcg-it8";
  app.add_option("--scene", scene_path, "scene file");
  app.add_option("--seconds", seconds, "simulated time, s")->check(fahr::cli::Range(0.001, 3600.0));
  bool no_reference = false;
  app.add_flag("--no-reference", no_reference,
               "do not add the exact run: the first configuration listed is the reference "
               "(profiling one configuration)");
  std::string script = "intubation";
  app.add_option("--script", script, "the simulated hand's script (overshoot: to 3x the limit)")
      ->check(fahr::cli::IsMember({"intubation", "overshoot"}));
  double support_ratio = -1.0;
  app.add_option("--support-ratio", support_ratio,
                 "the FEM's anatomy support springs over the node's diagonal of A (0: off); "
                 "default: the FEM's");
  double audit_from_s = 0.0;
  double audit_to_s = 3600.0;
  app.add_option("--audit-from", audit_from_s,
                 "W is audited from this simulated time on, s (a held state: the overshoot's "
                 "hold at 3x is 5.5-10.5 s)")
      ->check(fahr::cli::Range(0.0, 3600.0));
  app.add_option("--audit-to", audit_to_s, "... and up to this time, s")
      ->check(fahr::cli::Range(0.0, 3600.0));
  app.add_flag("--corrections", g_corrections,
               "also audit W corrected for the factor's lag to first order (dense solves of every "
               "column: slow)");
  app.add_option("--configs", config_list,
                 "comma-separated: exact, shipped, lagged, pcg-rot, pcg-rest, pcg-itN (the exact "
                 "run is always made)");
  if (const auto exit = app.parse(argc, argv)) return *exit;
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  try {
    markdown.begin("fem-tongue-press");
    const auto scene = scene::load_scene(scene_path);
    std::vector<Run> runs;
    // The first configuration is the reference the others are compared with.
    std::vector<std::string> names;
    if (!no_reference) names.push_back("exact");
    std::stringstream list(config_list);
    for (std::string name; std::getline(list, name, ',');) {
      if (!name.empty() && (name != "exact" || no_reference)) names.push_back(name);
    }
    for (const std::string& name : names) {
      Run run;
      if (!make_config(name, run.config)) {
        std::fprintf(stderr, "fem_tongue_press: unknown configuration '%s'\n", name.c_str());
        return 2;
      }
      stack_sim::StackOptions options;
      if (support_ratio >= 0.0) options.experiments.fem_support_ratio = support_ratio;
      options.script =
          script == "overshoot" ? device::Script::kOvershoot : device::Script::kIntubation;
      run.sim = std::make_unique<stack_sim::StackSim>(scene, options);
      run.shadow.setup = std::make_unique<fem_service::FemBodySetup>(
          fem_service::set_up_body(*scene, *run.sim->fem().setup().scene_body));
      run.shadow.setup->anatomy_settings = run.sim->fem().setup().anatomy_settings;
      run.shadow.step = std::make_unique<fem_service::ServiceStep>(*run.shadow.setup);
      if (!run.config.keep_scene_solver) {
        for (fem::Body* body : {&run.sim->body(), run.shadow.setup->body.get()}) {
          const std::string error = body->set_solver(run.config.solver);
          if (!error.empty()) {
            std::fprintf(stderr, "fem_tongue_press: %s: %s\n", name.c_str(), error.c_str());
            return 2;
          }
        }
      }
      if (run.config.w_on_step_only) {
        run.sim->body().set_compliance_refresh_with_factor(false);
        run.shadow.setup->body->set_compliance_refresh_with_factor(false);
      }
      if (run.config.w_refresh > 0) {
        run.sim->body().set_compliance_refresh(run.config.w_refresh);
        run.shadow.setup->body->set_compliance_refresh(run.config.w_refresh);
      }
      run.factorisations_at_start = run.sim->body().factorisations();
      run.shadow.factorisations_at_start = run.shadow.setup->body->factorisations();
      runs.push_back(std::move(run));
    }
    // After the runs have their places: the audit's solver points into its
    // assembly's arrays.
    for (Run& run : runs) start_audit(run.shadow);
    const auto steps = static_cast<std::uint64_t>(std::llround(seconds * 1000.0));
    LoadChurn churn;
    for (std::uint64_t k = 0; k < steps; ++k) {
      const bool fem_steps = common::executes_at(k, runs.front().sim->fem_period_steps());
      for (Run& run : runs) {
        // What its FEM takes in this step (the read rule: the haptic
        // output of the step before).
        if (fem_steps) run.fed = run.sim->contacts();
        run.sim->step();
        const double force = force_norm(run.sim->command());
        run.peak_force_n = std::max(run.peak_force_n, force);
        if (!run.sim->fem_stepped()) continue;
        const double cpu_ms = 1e-6 * static_cast<double>(run.sim->last_fem_step_cpu().count());
        run.cpu_all_ms.push_back(cpu_ms);
        if (blade_touches(run.fed)) run.cpu_touching_ms.push_back(cpu_ms);
        const auto& report = run.sim->fem().last_report();
        if (!report.asleep) run.iterations.push_back(report.solver_iterations);
        run.max_inverted = std::max(run.max_inverted, report.inverted_elements);
      }
      const Run& exact = runs.front();
      if (fem_steps && k > 0) {
        const double t_s = exact.sim->time_s();
        if (t_s >= audit_from_s && t_s <= audit_to_s) churn.add(exact.fed);
      }
      if (fem_steps) {
        // The shadows: the exact run's ContactSet, the same step.
        for (Run& run : runs) {
          Shadow& shadow = run.shadow;
          if (k > 0) shadow.step->take(exact.fed, exact.fed.header().seq());
          const double t0_s = exact.sim->time_s();
          if (t0_s >= audit_from_s && t0_s <= audit_to_s) {
            shadow.setup->body->assemble_current(shadow.start_assembly);
            const auto x0 = shadow.setup->body->positions_m();
            shadow.before_m.assign(x0.begin(), x0.end());
          }
          const std::int64_t cpu0 = common::thread_cpu_now_ns();
          shadow.step->step();
          const double cpu_ms = 1e-6 * static_cast<double>(common::thread_cpu_now_ns() - cpu0);
          if (blade_touches(exact.fed)) shadow.cpu_touching_ms.push_back(cpu_ms);
          const auto& report = shadow.step->last_report();
          const double t_s = exact.sim->time_s();
          if (!report.asleep && t_s >= audit_from_s && t_s <= audit_to_s) {
            audit_compliance(shadow, exact.fed);
          }
          if (!report.asleep) shadow.iterations.push_back(report.solver_iterations);
          shadow.max_inverted = std::max(shadow.max_inverted, report.inverted_elements);
          shadow.max_node_mm = std::max(
              shadow.max_node_mm, largest_node_distance_mm(exact.sim->body(), *shadow.setup->body));
          shadow.max_w_relative =
              std::max(shadow.max_w_relative,
                       w_difference(exact.sim->fem().contact_step(), shadow.step->contact_step()));
        }
      }
      for (std::size_t r = 1; r < runs.size(); ++r) {
        Run& run = runs[r];
        const double df = force_difference(exact.sim->command(), run.sim->command());
        run.max_force_n = std::max(run.max_force_n, df);
        run.force_sq_sum += df * df;
        ++run.force_samples;
        if (run.sim->fem_stepped()) {
          run.max_node_mm = std::max(run.max_node_mm,
                                     largest_node_distance_mm(exact.sim->body(), run.sim->body()));
        }
      }
    }
    std::printf(
        "fem_tongue_press: %s, %.1f s simulated, %zu configurations side by side, support ratio "
        "%s; FEM step CPU ms while the blade touches: closed loop the step's and the "
        "background factorisation's threads (what the factorisation used since the step "
        "before), open loop the step's thread\n\n",
        scene_path.c_str(), seconds, runs.size(),
        support_ratio >= 0.0 ? std::to_string(support_ratio).c_str() : "the FEM's default");
    std::printf("Closed loop (each configuration's own stack):\n\n");
    std::printf(
        "| configuration | CPU p50 / p99 / max | CPU all steps p99 | steps touching | "
        "refactorisations "
        "| CG iterations mean / max | node diff max, mm | force diff max / RMS, N | peak force, N "
        "| most "
        "inverted |\n");
    std::printf("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
    const auto mean_max = [](const std::vector<double>& v, double& mean, double& largest) {
      double sum = 0.0;
      largest = 0.0;
      for (const double x : v) {
        sum += x;
        largest = std::max(largest, x);
      }
      mean = v.empty() ? 0.0 : sum / static_cast<double>(v.size());
    };
    for (const Run& run : runs) {
      double iteration_mean = 0.0;
      double iteration_max = 0.0;
      mean_max(run.iterations, iteration_mean, iteration_max);
      const double rms = run.force_samples == 0
                             ? 0.0
                             : std::sqrt(run.force_sq_sum / static_cast<double>(run.force_samples));
      const bool reference = &run == &runs.front();
      std::printf(
          "| %s | %.2f / %.2f / %.2f | %.2f | %zu | %llu | %.1f / %.0f | %s | %s | %.3f | %d |\n",
          run.config.name.c_str(), quantile(run.cpu_touching_ms, 0.5),
          quantile(run.cpu_touching_ms, 0.99), quantile(run.cpu_touching_ms, 1.0),
          quantile(run.cpu_all_ms, 0.99), run.cpu_touching_ms.size(),
          static_cast<unsigned long long>(run.sim->body().factorisations() -
                                          run.factorisations_at_start),
          iteration_mean, iteration_max, cell(run.max_node_mm, reference).c_str(),
          reference ? "(reference)"
                    : (cell(run.max_force_n, false) + " / " + cell(rms, false)).c_str(),
          run.peak_force_n, run.max_inverted);
    }
    std::printf(
        "\nOpen loop (shadow FEMs fed the exact run's ContactSets; the exact shadow checks "
        "determinism):\n\n");
    std::printf(
        "| configuration | CPU p50 / p99 / max | refactorisations | CG iterations mean / max "
        "| node diff from exact max, mm | W diff from exact run max, relative | W error vs fresh "
        "factor, whole block, p50 / p99 / max (steps) | most inverted |\n");
    std::printf("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n");
    for (const Run& run : runs) {
      const Shadow& shadow = run.shadow;
      double iteration_mean = 0.0;
      double iteration_max = 0.0;
      mean_max(shadow.iterations, iteration_mean, iteration_max);
      char audit[96] = "-";
      const auto& whole = shadow.start_error.back();
      std::snprintf(audit, sizeof audit, "%.3g / %.3g / %.3g (%zu)", quantile(whole, 0.5),
                    quantile(whole, 0.99), quantile(whole, 1.0), whole.size());
      std::printf("| %s | %.2f / %.2f / %.2f | %llu | %.1f / %.0f | %.3g | %.3g | %s | %d |\n",
                  run.config.name.c_str(), quantile(shadow.cpu_touching_ms, 0.5),
                  quantile(shadow.cpu_touching_ms, 0.99), quantile(shadow.cpu_touching_ms, 1.0),
                  static_cast<unsigned long long>(shadow.setup->body->factorisations() -
                                                  shadow.factorisations_at_start),
                  iteration_mean, iteration_max, shadow.max_node_mm, shadow.max_w_relative, audit,
                  shadow.max_inverted);
    }
    const auto print_errors = [&](const char* title, auto errors_of) {
      std::printf(
          "\n%s (open loop, every awake step from %.2f to %.2f s): relative Frobenius error of "
          "the leading spheres' block, p99 / max (steps)\n\n",
          title, audit_from_s, std::min(audit_to_s, seconds));
      std::printf("| configuration | 1 sphere | 8 | 32 | 64 | whole block |\n");
      std::printf("| --- | ---: | ---: | ---: | ---: | ---: |\n");
      for (const Run& run : runs) {
        std::printf("| %s", run.config.name.c_str());
        for (const auto& errors : errors_of(run.shadow)) {
          std::printf(" | %.3g / %.3g (%zu)", quantile(errors, 0.99), quantile(errors, 1.0),
                      errors.size());
        }
        std::printf(" |\n");
      }
    };
    print_errors(
        "W against the current linearised compliance: A at the state the step solves from, every "
        "tangent afresh, the anatomy's supports the step holds",
        [](const Shadow& shadow) -> const auto& { return shadow.start_error; });
    print_errors(
        "W against A linearised at the state after the step (the next step's system: what one "
        "step changes in the tissue's linearisation)",
        [](const Shadow& shadow) -> const auto& { return shadow.audit_error; });
    std::printf(
        "\nThe tool's rows solved on each W (the rows of the set the step took that carry a "
        "force, on spheres of the block; the displacement the haptic side's forces make under "
        "the W in use, solved for on the fresh W by PGS): relative difference of the resultant, "
        "p50 / p99 / max (steps)\n\n");
    std::printf(
        "| configuration | against the start state's A | against A after the step | PGS's own "
        "floor, max | rows without a W slot |\n");
    std::printf("| --- | ---: | ---: | ---: | ---: |\n");
    for (const Run& run : runs) {
      const Shadow& sh = run.shadow;
      const auto cell3 = [](const std::vector<double>& v) {
        char text[96];
        std::snprintf(text, sizeof text, "%.3g / %.3g / %.3g (%zu)", quantile(v, 0.5),
                      quantile(v, 0.99), quantile(v, 1.0), v.size());
        return std::string(text);
      };
      std::printf("| %s | %s | %s | %.2g | %zu |\n", run.config.name.c_str(),
                  cell3(sh.start_force_error).c_str(), cell3(sh.audit_force_error).c_str(),
                  sh.force_floor_max, sh.rows_outside_block);
    }
    std::printf(
        "\nThe tool's load moved between spheres from one ContactSet the FEM took to the next "
        "(the %s run's sets; sum over spheres of the change of their force over the larger "
        "sum: 0 the same split, 2 no sphere in common), p50 / p99 / max (%zu sets): %.3g / "
        "%.3g / %.3g\n",
        runs.front().config.name.c_str(), churn.shares.size(), quantile(churn.shares, 0.5),
        quantile(churn.shares, 0.99), quantile(churn.shares, 1.0));
    std::printf(
        "Of the spheres carrying the tool's load in a set, the share that carried it in the set "
        "before, p50 / p1 / min: %.3g / %.3g / %.3g\n",
        quantile(churn.kept, 0.5), quantile(churn.kept, 0.01), quantile(churn.kept, 0.0));
    if (g_corrections) {
      using Errors = std::array<std::vector<double>, 5> Shadow::*;
      const std::array<std::pair<const char*, Errors>, 3> corrections{{
          {"Every column solved on the factor in use (dense solves), against the start state's A",
           &Shadow::lagged_error},
          {"The same columns corrected to first order in A - A_f (W = h^2 (2 J X - X^T A X)), "
           "against the start state's A",
           &Shadow::first_order_error},
          {"... after one refinement of the columns (X + A_f^-1 (J^T - A X)), against the start "
           "state's A",
           &Shadow::refined_error},
      }};
      for (const auto& correction : corrections) {
        const Errors member = correction.second;  // a structured binding is not capturable here
        print_errors(
            correction.first, [member](const Shadow& shadow) -> const auto& {
              return shadow.*member;
            });
      }
      for (const Run& run : runs) {
        std::printf(
            "- %s: the corrections' audit took at most %.1f ms a step (dense, not the "
            "shipped cost)\n",
            run.config.name.c_str(), run.shadow.correction_ms_max);
        // One sphere's error by the held set's changes since the factor.
        const Shadow& sh = run.shadow;
        for (const auto& [low, high] :
             {std::pair<std::size_t, std::size_t>{0, 0}, {1, 3}, {4, 1000000}}) {
          std::vector<double> lagged, first;
          for (std::size_t i = 0; i < sh.support_changes.size(); ++i) {
            if (sh.support_changes[i] < low || sh.support_changes[i] > high) continue;
            lagged.push_back(sh.lagged_error[0][i]);
            first.push_back(sh.first_order_error[0][i]);
          }
          if (lagged.empty()) continue;
          std::printf(
              "  - held set changed by %zu-%zu nodes since the factor: %zu steps, one "
              "sphere p50 / p99: lagged %.3g / %.3g, first order %.3g / %.3g\n",
              low, high, lagged.size(), quantile(lagged, 0.5), quantile(lagged, 0.99),
              quantile(first, 0.5), quantile(first, 0.99));
        }
      }
    }
    std::printf(
        "\nThe largest node motion in an audited step, mm, p50 / p99 / max, and the steps in which "
        "that node moved against its motion in the step before:\n\n");
    for (const Run& run : runs) {
      const Shadow& shadow = run.shadow;
      std::printf("- %s: %.3g / %.3g / %.3g; %zu of %zu steps reversed\n", run.config.name.c_str(),
                  quantile(shadow.step_motion_mm, 0.5), quantile(shadow.step_motion_mm, 0.99),
                  quantile(shadow.step_motion_mm, 1.0), shadow.reversals,
                  shadow.step_motion_mm.size());
    }
    print_kernel_costs(runs.front().sim->body());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fem_tongue_press: %s\n", e.what());
    return 2;
  }
} catch (const std::exception& e) {
  std::fprintf(stderr, "fem_tongue_press: %s\n", e.what());
  return 1;
}
