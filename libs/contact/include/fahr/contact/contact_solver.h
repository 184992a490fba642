// The tool's contact problem on the FEM's compliance, one tick: builds the
// Delassus matrix A_ij = n_i^T W_ij n_j of the rows, solves for lambda >= 0
// with projected Gauss-Seidel (warm-started per row key), and gives the local
// stiffness of the active set. Capacities are fixed at construction; nothing
// allocates afterwards. The formulation is derived in docs/design/force-aware-decision.md.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

#include "fahr/contact/contact_row.h"
#include "fahr/contact/pgs.h"
#include "fahr/contact/tissue_compliance.h"

namespace fahr::contact {

struct SolverLoadReport {
  std::size_t rows = 0;        // rows loaded
  bool overflow = false;       // more rows than capacity: the extra rows were dropped
  int missing_compliance = 0;  // tissue rows without a W block: left out of the solve
  int degenerate_normals = 0;  // rows whose normal is not unit length: dropped
  // The tissue rows' A was not positive semidefinite (W's columns from
  // different factorisations of the FEM: ContactSolver::load) and its
  // diagonal was scaled by this, > 1, to make it so; 1 otherwise.
  double diagonal_scale = 1.0;
  bool indefinite = false;  // not semidefinite even with the largest scale
};

class ContactSolver {
 public:
  // capacity: rows per tick (the DeformationState carries at most 64 spheres).
  explicit ContactSolver(std::size_t capacity);

  // Copies the rows (in order) and builds A from `compliance`. A tissue row
  // without a block in it is left out and counted (no constant stands in
  // for the tissue); obstacle rows get 0 (rigid). An A that is not positive
  // semidefinite has its diagonal scaled up until it is (the report says
  // by how much). Warm starts lambda from the previous stored solution with
  // the same (kind, id).
  SolverLoadReport load(std::span<const ContactRow> rows, const TissueCompliance& compliance);

  // W = 0 for every row (the naive loop: the tissue does not yield).
  void make_rigid();

  // The proxy in equilibrium with a coupling of stiffness k_eff (N/m, > 0)
  // pulling it toward a target displaced by `target_offset_m` = x_t - p0:
  //   (A + N^T N / k_eff) lambda >= d + N^T (x_t - p0),  lambda >= 0, compl.
  // Returns the proxy displacement p - p0 = (x_t - p0) - N lambda / k_eff.
  Eigen::Vector3d solve_coupled(double k_eff_npm, const Eigen::Vector3d& target_offset_m,
                                const PgsSettings& settings);

  // The proxy held at p0 + proxy_offset_m: A lambda >= d + N^T offset. Rows
  // that cannot yield (A_ii = 0: obstacles, fully fixed spheres) carry no
  // force here, since a held proxy needs none from them. With `facing`
  // non-zero, tissue rows whose normal points against it (n . facing < 0)
  // take no part and keep lambda = 0: the load a held tool puts on the
  // tissue along the push it froze with (ContactResponse, kHoldLoad).
  void solve_pinned(const Eigen::Vector3d& proxy_offset_m, const PgsSettings& settings,
                    const Eigen::Vector3d& facing = Eigen::Vector3d::Zero());

  // The proxy step nearest `step_m` that leaves no obstacle row penetrating
  // (n_i . step <= -d_i for every obstacle row): what a held or catching-up
  // proxy may do, since the pinned solve gives obstacles no force. A
  // projection onto a polyhedron, solved as the LCP (N_o^T N_o) mu >=
  // d_o + N_o^T step by PGS; returns step - N_o mu. Leaves lambda alone.
  Eigen::Vector3d project_on_obstacles(const Eigen::Vector3d& step_m, const PgsSettings& settings);
  bool has_obstacle_rows() const;

  // K = N_S (A_S + N_S^T N_S / k_c)^-1 N_S^T over rows with lambda > 0, N/m:
  // d(force on the stylus)/d(device position) = -K. Symmetric PSD, <= k_c.
  Eigen::Matrix3d local_stiffness(double k_c_npm);

  // Remembers lambda per (kind, id) for the next tick's warm start.
  void store_warm_start();
  void clear_warm_start() { previous_count_ = 0; }
  // Starts the next solve of this tick from lambda = 0 (after a solve that
  // left it meaningless).
  void clear_lambda() { std::fill(lambda_.begin(), lambda_.end(), 0.0); }

  std::size_t size() const { return k_; }
  std::size_t capacity() const { return capacity_; }
  const ContactRow& row(std::size_t i) const { return rows_[i]; }
  double lambda(std::size_t i) const { return lambda_[i]; }
  double penetration(std::size_t i) const { return depth_[i]; }  // d_i at p0, m
  // sum_i n_i lambda_i over rows of `kind`, N (the force the tool exerts on them).
  Eigen::Vector3d resultant(RowKind kind) const;
  // The same over the rows of `kind` whose id lies in [first_id, end_id).
  Eigen::Vector3d resultant(RowKind kind, std::uint32_t first_id, std::uint32_t end_id) const;
  // W_row(i),row(j) n_j summed with lambda_j over tissue rows: the predicted
  // motion of row i's sphere centre under the solved forces, m.
  Eigen::Vector3d predicted_motion(std::size_t i, const TissueCompliance& compliance) const;
  const PgsReport& last_report() const { return report_; }
  // PGS work since the last reset_work() (every solve and projection).
  const PgsWork& work() const { return work_; }
  void reset_work() { work_ = PgsWork{}; }

 private:
  std::size_t capacity_;
  std::size_t k_ = 0;
  std::vector<ContactRow> rows_;
  // Makes A positive semidefinite (load()); the report says how.
  void make_semidefinite(SolverLoadReport& report);

  std::vector<double> a_;         // Delassus A, capacity^2, m/N
  std::vector<double> s_;         // system matrix of the current solve, capacity^2, m/N
  std::vector<double> b_;         // right-hand side, m
  std::vector<double> depth_;     // d at p0, m
  std::vector<double> lambda_;    // N
  std::vector<double> residual_;  // PGS workspace, m
  std::vector<std::uint64_t> previous_keys_;
  std::vector<double> previous_lambda_;
  std::size_t previous_count_ = 0;
  std::vector<std::uint32_t> active_;         // rows of the active set (local stiffness)
  std::vector<double> factor_;                // capacity^2
  std::vector<double> columns_;               // 3 x capacity right-hand sides
  std::vector<std::uint32_t> obstacle_rows_;  // project_on_obstacles: its rows, matrix, rhs, mu
  std::vector<double> projection_s_;
  std::vector<double> projection_b_;
  std::vector<double> projection_mu_;
  PgsReport report_;
  PgsWork work_;
};

}  // namespace fahr::contact
