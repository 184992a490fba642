// Delassus assembly, coupled and pinned solves, and the active-set stiffness.
#include "fahr/contact/contact_solver.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "fahr/contact/dense_cholesky.h"

namespace fahr::contact {
namespace {

// A projection onto the obstacles may push the tool by its deepest row's
// depth plus this, m; more means the rows contradict each other.
constexpr double kProjectionSlackM = 1e-3;

// Normals are unit by contract; one off by more than this is a caller bug
// (or c == q at the collision stage) and its row is dropped.
constexpr double kUnitNormalTolerance = 1e-3;

// Smallest pivot of the active-set factorisation, m/N: A + N^T N/K_c is
// singular only for redundant rigid rows (more than three obstacle normals);
// 1e-12 m/N there means a 1e12 N/m direction that the final clamp to K_c
// (docs/design/force-aware-decision.md) makes harmless.
constexpr double kMinPivotMpn = 1e-12;

// A pivot of A's factorisation below -this x its diagonal entry makes A
// indefinite; within it of zero, a row depends on the rows before it
// (neighbouring spheres under one blade face; W is stored in float).
constexpr double kSemidefiniteTolerance = 1e-4;
// Scales tried on an indefinite A's diagonal: 1 + 1/16, 1 + 1/8, ... 1 + 4.
constexpr double kFirstDiagonalShift = 1.0 / 16.0;
constexpr double kLargestDiagonalShift = 4.0;

// A left-out row's right-hand side: a gap of a metre, which no solve of
// tissue compliances (~1e-3 m/N) and rows' forces can close, so PGS keeps
// its lambda at 0.
constexpr double kLeftOutGapM = -1.0;

std::uint64_t row_key(const ContactRow& row) {
  return (std::uint64_t{row.kind == RowKind::kObstacle ? 1u : 0u} << 32) | row.id;
}

}  // namespace

ContactSolver::ContactSolver(std::size_t capacity)
    : capacity_(capacity),
      rows_(capacity),
      a_(capacity * capacity, 0.0),
      s_(capacity * capacity, 0.0),
      b_(capacity, 0.0),
      depth_(capacity, 0.0),
      lambda_(capacity, 0.0),
      residual_(capacity, 0.0),
      previous_keys_(capacity, 0),
      previous_lambda_(capacity, 0.0),
      active_(capacity, 0),
      factor_(capacity * capacity, 0.0),
      columns_(3 * capacity, 0.0),
      obstacle_rows_(capacity, 0),
      projection_s_(capacity * capacity, 0.0),
      projection_b_(capacity, 0.0),
      projection_mu_(capacity, 0.0) {}

SolverLoadReport ContactSolver::load(std::span<const ContactRow> rows,
                                     const TissueCompliance& compliance) {
  SolverLoadReport report;
  k_ = 0;
  const bool have_w = compliance.valid();
  for (const ContactRow& row : rows) {
    if (std::abs(row.normal.squaredNorm() - 1.0) > kUnitNormalTolerance ||
        !row.normal.allFinite()) {
      ++report.degenerate_normals;
      continue;
    }
    const bool has_block = row.kind == RowKind::kTissue && have_w && row.compliance_index >= 0 &&
                           static_cast<std::size_t>(row.compliance_index) < compliance.size();
    if (row.kind == RowKind::kTissue && !has_block) {
      // No constant stands in for the tissue's compliance: the row is left out.
      ++report.missing_compliance;
      continue;
    }
    if (k_ == capacity_) {
      report.overflow = true;
      break;
    }
    rows_[k_] = row;
    if (row.kind != RowKind::kTissue) rows_[k_].compliance_index = kNoCompliance;
    depth_[k_] = row.penetration_m();
    ++k_;
  }
  // A_ij = n_i^T W_ij n_j for tissue rows; zero for obstacles (rigid).
  // Filled for j <= i and mirrored: W's stored blocks are symmetric only to
  // float rounding, and the PGS relies on an exactly symmetric S.
  for (std::size_t i = 0; i < k_; ++i) {
    const ContactRow& ri = rows_[i];
    for (std::size_t j = 0; j <= i; ++j) {
      const ContactRow& rj = rows_[j];
      double value = 0.0;
      if (ri.compliance_index != kNoCompliance && rj.compliance_index != kNoCompliance) {
        value =
            compliance.normal_compliance(static_cast<std::size_t>(ri.compliance_index), ri.normal,
                                         static_cast<std::size_t>(rj.compliance_index), rj.normal);
      }
      a_[i * capacity_ + j] = value;
      a_[j * capacity_ + i] = value;
    }
  }
  report.rows = k_;
  make_semidefinite(report);
  // Warm start: the previous tick's lambda of the same (kind, id).
  for (std::size_t i = 0; i < k_; ++i) {
    const std::uint64_t key = row_key(rows_[i]);
    lambda_[i] = 0.0;
    for (std::size_t m = 0; m < previous_count_; ++m) {
      if (previous_keys_[m] == key) {
        lambda_[i] = previous_lambda_[m];
        break;
      }
    }
  }
  return report;
}

// W = h^2 J A^-1 J^T is positive semidefinite, and so is the rows' A built
// from it. The FEM's block is not always one W: its kept columns are solved
// again on a new factorisation a few spheres a step (fem::ComplianceBlock),
// so for a while neighbouring spheres' columns come from factorisations of
// a tissue that has stiffened in between. Two spheres under one blade face
// have nearly equal columns, and where their diagonals come from different
// factorisations, [[a, c], [c, b]] with c close to the larger of a and b is
// indefinite. PGS can diverge on an indefinite A (it did in real-time runs
// of the neonatal scene: 1e6 N after one tick, growing each tick through the warm
// start). The smallest of the tried scales of the tissue rows' diagonal
// that makes A semidefinite is applied: each such row a little more
// compliant than the block says, by about the change between the
// factorisations. Costs one factorisation of A, k^3/6, per tick.
void ContactSolver::make_semidefinite(SolverLoadReport& report) {
  double scale = 1.0;
  while (!semidefinite(a_.data(), capacity_, k_, scale, kSemidefiniteTolerance, factor_.data())) {
    const double shift = scale == 1.0 ? kFirstDiagonalShift : 2.0 * (scale - 1.0);
    if (shift > kLargestDiagonalShift) {
      report.indefinite = true;
      return;
    }
    scale = 1.0 + shift;
  }
  for (std::size_t i = 0; i < k_ && scale != 1.0; ++i) a_[i * capacity_ + i] *= scale;
  report.diagonal_scale = scale;
}

void ContactSolver::make_rigid() {
  for (std::size_t i = 0; i < k_; ++i) {
    for (std::size_t j = 0; j < k_; ++j) a_[i * capacity_ + j] = 0.0;
  }
}

Eigen::Vector3d ContactSolver::solve_coupled(double k_eff_npm,
                                             const Eigen::Vector3d& target_offset_m,
                                             const PgsSettings& settings) {
  const double inverse_k = 1.0 / k_eff_npm;
  for (std::size_t i = 0; i < k_; ++i) {
    const Eigen::Vector3d& ni = rows_[i].normal;
    for (std::size_t j = 0; j < k_; ++j) {
      s_[i * capacity_ + j] = a_[i * capacity_ + j] + ni.dot(rows_[j].normal) * inverse_k;
    }
    b_[i] = depth_[i] + ni.dot(target_offset_m);
  }
  report_ =
      solve_pgs(s_.data(), capacity_, k_, b_.data(), lambda_.data(), residual_.data(), settings);
  work_.add(report_, k_);
  Eigen::Vector3d push = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < k_; ++i) push += rows_[i].normal * lambda_[i];
  return target_offset_m - push * inverse_k;
}

void ContactSolver::solve_pinned(const Eigen::Vector3d& proxy_offset_m, const PgsSettings& settings,
                                 const Eigen::Vector3d& facing) {
  for (std::size_t i = 0; i < k_; ++i) {
    for (std::size_t j = 0; j < k_; ++j) s_[i * capacity_ + j] = a_[i * capacity_ + j];
    b_[i] = depth_[i] + rows_[i].normal.dot(proxy_offset_m);
    if (rows_[i].kind == RowKind::kTissue && rows_[i].normal.dot(facing) < 0.0) {
      b_[i] = kLeftOutGapM;
      lambda_[i] = 0.0;
    }
  }
  report_ =
      solve_pgs(s_.data(), capacity_, k_, b_.data(), lambda_.data(), residual_.data(), settings);
  work_.add(report_, k_);
}

bool ContactSolver::has_obstacle_rows() const {
  for (std::size_t i = 0; i < k_; ++i) {
    if (rows_[i].kind == RowKind::kObstacle) return true;
  }
  return false;
}

Eigen::Vector3d ContactSolver::project_on_obstacles(const Eigen::Vector3d& step_m,
                                                    const PgsSettings& settings) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < k_; ++i) {
    if (rows_[i].kind == RowKind::kObstacle) obstacle_rows_[n++] = static_cast<std::uint32_t>(i);
  }
  if (n == 0) return step_m;
  for (std::size_t a = 0; a < n; ++a) {
    const Eigen::Vector3d& na = rows_[obstacle_rows_[a]].normal;
    for (std::size_t b = 0; b < n; ++b)
      projection_s_[a * capacity_ + b] = na.dot(rows_[obstacle_rows_[b]].normal);
    projection_b_[a] = depth_[obstacle_rows_[a]] + na.dot(step_m);
    projection_mu_[a] = 0.0;
  }
  double deepest = 0.0;
  for (std::size_t a = 0; a < n; ++a) deepest = std::max(deepest, projection_b_[a]);
  work_.add(solve_pgs(projection_s_.data(), capacity_, n, projection_b_.data(),
                      projection_mu_.data(), residual_.data(), settings),
            n);
  Eigen::Vector3d push = Eigen::Vector3d::Zero();
  for (std::size_t a = 0; a < n; ++a) push += rows_[obstacle_rows_[a]].normal * projection_mu_[a];
  // Rows pinching the tool from opposite sides have no common solution and
  // mu grows without bound: then no push is trusted beyond the deepest row
  // (the tool is stuck in the bone it is in, not thrown out of the mouth).
  if (!push.allFinite() || push.norm() > deepest + kProjectionSlackM) return step_m;
  return step_m - push;
}

Eigen::Matrix3d ContactSolver::local_stiffness(double k_c_npm) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < k_; ++i) {
    if (lambda_[i] > 0.0) active_[n++] = static_cast<std::uint32_t>(i);
  }
  Eigen::Matrix3d k = Eigen::Matrix3d::Zero();
  if (n == 0) return k;
  const double inverse_k = 1.0 / k_c_npm;
  for (std::size_t a = 0; a < n; ++a) {
    const ContactRow& ra = rows_[active_[a]];
    for (std::size_t b = 0; b <= a; ++b) {
      const ContactRow& rb = rows_[active_[b]];
      factor_[a * capacity_ + b] =
          a_[active_[a] * capacity_ + active_[b]] + ra.normal.dot(rb.normal) * inverse_k;
    }
  }
  cholesky_in_place(factor_.data(), capacity_, n, kMinPivotMpn);
  // Column c of K: N_S S^-1 (N_S^T e_c).
  for (Eigen::Index c = 0; c < 3; ++c) {
    double* x = columns_.data();
    for (std::size_t a = 0; a < n; ++a) x[a] = rows_[active_[a]].normal[c];
    cholesky_solve(factor_.data(), capacity_, n, x);
    for (std::size_t a = 0; a < n; ++a) k.col(c) += rows_[active_[a]].normal * x[a];
  }
  // Symmetric by construction; rounding and the pivot floor can leave it a
  // hair off or above K_c along a redundant direction: symmetrise and clamp
  // its eigenvalues to [0, K_c] so the gateway never renders more than K_c.
  k = 0.5 * (k + k.transpose()).eval();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(k);
  const Eigen::Vector3d values = eigen.eigenvalues().cwiseMax(0.0).cwiseMin(k_c_npm);
  return eigen.eigenvectors() * values.asDiagonal() * eigen.eigenvectors().transpose();
}

void ContactSolver::store_warm_start() {
  for (std::size_t i = 0; i < k_; ++i) {
    previous_keys_[i] = row_key(rows_[i]);
    previous_lambda_[i] = lambda_[i];
  }
  previous_count_ = k_;
}

Eigen::Vector3d ContactSolver::resultant(RowKind kind) const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < k_; ++i) {
    if (rows_[i].kind == kind) sum += rows_[i].normal * lambda_[i];
  }
  return sum;
}

Eigen::Vector3d ContactSolver::resultant(RowKind kind, std::uint32_t first_id,
                                         std::uint32_t end_id) const {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < k_; ++i) {
    const ContactRow& r = rows_[i];
    if (r.kind == kind && r.id >= first_id && r.id < end_id) sum += r.normal * lambda_[i];
  }
  return sum;
}

Eigen::Vector3d ContactSolver::predicted_motion(std::size_t i,
                                                const TissueCompliance& compliance) const {
  Eigen::Vector3d motion = Eigen::Vector3d::Zero();
  const ContactRow& ri = rows_[i];
  if (ri.compliance_index == kNoCompliance) return motion;
  for (std::size_t j = 0; j < k_; ++j) {
    const ContactRow& rj = rows_[j];
    if (rj.compliance_index == kNoCompliance || lambda_[j] == 0.0) continue;
    motion += compliance.column(static_cast<std::size_t>(ri.compliance_index),
                                static_cast<std::size_t>(rj.compliance_index), rj.normal) *
              lambda_[j];
  }
  return motion;
}

}  // namespace fahr::contact
