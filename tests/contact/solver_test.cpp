// The contact solve: PGS, the coupled and pinned problems, the local
// stiffness, rigid obstacles and the warm start.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>
#include <vector>

#include "fahr/contact/contact_solver.h"
#include "fahr/contact/coupling.h"
#include "fahr/contact/dense_cholesky.h"
#include "fahr/contact/pgs.h"
#include "synthetic.h"

namespace fahr::contact {
namespace {

TEST(Pgs, SolvesAKnownComplementarityProblem) {
  // S = [2 1; 1 2], b = [1, -1]: lambda_2 = 0 (separating), lambda_1 = 1/2.
  const double s[4] = {2, 1, 1, 2};
  const double b[2] = {1, -1};
  double lambda[2] = {0, 0};
  double residual[2];
  const PgsReport report = solve_pgs(s, 2, 2, b, lambda, residual, PgsSettings{});
  EXPECT_TRUE(report.converged);
  EXPECT_NEAR(lambda[0], 0.5, 1e-9);
  EXPECT_EQ(lambda[1], 0.0);
}

// Many coupled rows, like a blade on a tongue: S = G G^T + small diagonal
// from random directions (strongly coupled, as neighbouring spheres are),
// half the right-hand sides separating. The solution satisfies the
// complementarity conditions, and the residual handed back is b - S lambda.
TEST(Pgs, CoupledRowsMeetTheComplementarityConditions) {
  const std::size_t k = 48;
  const std::size_t stride = 50;
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<double> g(k * 6);
  for (double& v : g) v = uniform(random);
  std::vector<double> s(k * stride, 0.0);
  for (std::size_t i = 0; i < k; ++i) {
    for (std::size_t j = 0; j < k; ++j) {
      double dot = i == j ? 0.05 : 0.0;
      for (std::size_t d = 0; d < 6; ++d) dot += g[i * 6 + d] * g[j * 6 + d];
      s[i * stride + j] = 1e-3 * dot;  // m/N
    }
  }
  std::vector<double> b(k), lambda(k, 0.0), residual(k);
  for (double& v : b) v = 1e-3 * uniform(random);  // m
  PgsSettings settings;
  settings.max_sweeps = 5000;
  const PgsReport report =
      solve_pgs(s.data(), stride, k, b.data(), lambda.data(), residual.data(), settings);
  EXPECT_TRUE(report.converged);
  int active = 0;
  for (std::size_t i = 0; i < k; ++i) {
    double w = -b[i];  // S lambda - b: the gap left open, m
    for (std::size_t j = 0; j < k; ++j) w += s[i * stride + j] * lambda[j];
    EXPECT_GE(lambda[i], 0.0);
    EXPECT_GT(w, -1e-7) << "row " << i;
    if (lambda[i] > 0.0) {
      ++active;
      EXPECT_NEAR(w, 0.0, 1e-7) << "row " << i;
    }
    EXPECT_NEAR(residual[i], -w, 1e-12) << "row " << i;
  }
  EXPECT_GT(active, 2);
  EXPECT_LT(active, static_cast<int>(k));
}

TEST(ContactSolver, OneRowBalancesTheCouplingAgainstTheTissue) {
  test::SyntheticPatch patch = test::make_patch(1, -0.001, 0.004, 0.0);  // 1 mm penetration
  ContactSolver solver(8);
  solver.load(patch.rows, patch.compliance());
  const double k = 500.0;
  const Eigen::Vector3d target(0, -0.002, 0);  // device 2 mm further down
  const Eigen::Vector3d step = solver.solve_coupled(k, target, PgsSettings{});
  // (A + 1/K) lambda = d + n . target
  const double expected = (0.001 + 0.002) / (0.004 + 1.0 / k);
  EXPECT_NEAR(solver.lambda(0), expected, 1e-6 * expected);
  // Proxy equilibrium: K (x_t - p) = n lambda.
  EXPECT_NEAR((k * (target - step)).y(), -expected, 1e-6 * expected);
  // Stiffness along y: 1 / (A + 1/K), below K.
  const Eigen::Matrix3d stiffness = solver.local_stiffness(k);
  // W is float: relative 1e-6.
  EXPECT_NEAR(stiffness(1, 1), 1.0 / (0.004 + 1.0 / k), 1e-6 * stiffness(1, 1));
  EXPECT_NEAR(stiffness(0, 0), 0.0, 1e-9);
}

TEST(TissueCompliance, AlongNormalsReadsAsTheBlocksForTheFemsNormalAndItsOpposite) {
  // A random symmetric 3x3-block W of 3 spheres; the same W along the FEM's
  // normals m_t (one column a sphere) gives n_s . W_st n_t exactly for
  // n_t = +-m_t, and a turned n_t only its part along m_t.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const std::size_t k = 3;
  Eigen::MatrixXd b(3 * k, 3 * k);
  for (Eigen::Index i = 0; i < b.size(); ++i) b.data()[i] = u(rng);
  const Eigen::MatrixXd w = 1e-3 * b * b.transpose();
  const std::vector<std::uint32_t> ids = {4, 9, 2};
  std::vector<float> blocks(9 * k * k), along(3 * k * k), normals(3 * k);
  std::vector<Eigen::Vector3d> m(k);
  for (std::size_t t = 0; t < k; ++t) {
    m[t] = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    for (std::size_t d = 0; d < 3; ++d)
      normals[3 * t + d] = static_cast<float>(m[t][static_cast<Eigen::Index>(d)]);
  }
  for (std::size_t r = 0; r < 3 * k; ++r) {
    for (std::size_t c = 0; c < 3 * k; ++c) {
      blocks[r * 3 * k + c] =
          static_cast<float>(w(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)));
    }
    for (std::size_t t = 0; t < k; ++t) {
      // Through the float normals, as the FEM's columns are.
      const Eigen::Vector3d mt(normals[3 * t], normals[3 * t + 1], normals[3 * t + 2]);
      const Eigen::RowVector3d row =
          w.block<1, 3>(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(3 * t));
      along[r * k + t] = static_cast<float>(row.dot(mt.transpose()));
    }
  }
  const TissueCompliance full{1, ids, blocks, {}};
  const TissueCompliance by_normals{1, ids, along, normals};
  ASSERT_TRUE(full.valid());
  ASSERT_TRUE(by_normals.valid());
  EXPECT_TRUE(by_normals.along_normals());
  const TissueCompliance short_normals{1, ids, along, {normals.data(), 3 * k - 1}};
  EXPECT_FALSE(short_normals.valid());
  for (std::size_t s = 0; s < k; ++s) {
    for (std::size_t t = 0; t < k; ++t) {
      const Eigen::Vector3d mt(normals[3 * t], normals[3 * t + 1], normals[3 * t + 2]);
      for (const double sign : {1.0, -1.0}) {
        const Eigen::Vector3d n = sign * mt;
        EXPECT_NEAR(by_normals.normal_compliance(s, m[s], t, n),
                    full.normal_compliance(s, m[s], t, n), 1e-9);
        EXPECT_LT((by_normals.column(s, t, n) - full.column(s, t, n)).norm(), 1e-9);
      }
      const Eigen::Vector3d turned = (mt + 0.05 * mt.unitOrthogonal()).normalized();
      EXPECT_LT((by_normals.column(s, t, turned) - turned.dot(mt) * full.column(s, t, mt)).norm(),
                1e-9);
    }
  }
}

TEST(ContactSolver, LocalStiffnessIsSymmetricAndBoundedByTheCoupling) {
  test::SyntheticPatch patch = test::make_patch(12, 0.002, 0.002, 0.0005);
  // Tilt the normals so the active set spans several directions.
  for (std::size_t i = 0; i < patch.rows.size(); ++i) {
    const double angle = 0.3 * static_cast<double>(i) / 12.0;
    patch.rows[i].normal =
        Eigen::Vector3d(std::sin(angle), -std::cos(angle), 0.1 * angle).normalized();
  }
  ContactSolver solver(16);
  solver.load(patch.rows, patch.compliance());
  const double k = 1480.0;
  solver.solve_coupled(k, Eigen::Vector3d(0.001, -0.003, 0), PgsSettings{});
  const Eigen::Matrix3d stiffness = solver.local_stiffness(k);
  EXPECT_LT((stiffness - stiffness.transpose()).norm(), 1e-9 * k);
  const Eigen::Vector3d eigen =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(stiffness).eigenvalues();
  EXPECT_GE(eigen.minCoeff(), -1e-9);
  EXPECT_LE(eigen.maxCoeff(), k * (1 + 1e-12));
}

TEST(ContactSolver, RigidObstacleStopsTheProxy) {
  ContactRow wall;
  wall.kind = RowKind::kObstacle;
  wall.id = 3;
  wall.normal = Eigen::Vector3d(1, 0, 0);  // the obstacle lies in +x of the tool
  wall.tool_point_m = Eigen::Vector3d(0, 0, 0);
  wall.other_point_m = Eigen::Vector3d(0.0005, 0, 0);  // 0.5 mm gap
  ContactSolver solver(4);
  solver.load({&wall, 1}, TissueCompliance{});
  const double k = 400.0;
  const Eigen::Vector3d step = solver.solve_coupled(k, Eigen::Vector3d(0.01, 0, 0), PgsSettings{});
  EXPECT_NEAR(step.x(), 0.0005, 1e-9);  // touches, does not enter
  EXPECT_NEAR(solver.lambda(0), k * (0.01 - 0.0005), 1e-6);
}

// A tissue row the FEM sent no compliance for is not solved on a made-up
// constant: it is left out, counted, and pushes neither tool nor tissue.
TEST(ContactSolver, TissueRowWithoutComplianceIsLeftOutAndCounted) {
  test::SyntheticPatch patch = test::make_patch(4, 0.001, 0.001, 0.0001);
  std::vector<ContactRow> rows(patch.rows.begin(), patch.rows.end());
  rows[1].compliance_index = kNoCompliance;
  rows[3].compliance_index = static_cast<std::int32_t>(patch.compliance().size());  // unknown
  ContactSolver solver(8);
  const SolverLoadReport report = solver.load(rows, patch.compliance());
  EXPECT_EQ(report.missing_compliance, 2);
  ASSERT_EQ(report.rows, 2u);
  EXPECT_EQ(solver.row(0).id, rows[0].id);
  EXPECT_EQ(solver.row(1).id, rows[2].id);
  const SolverLoadReport none = solver.load(rows, TissueCompliance{});
  EXPECT_EQ(none.missing_compliance, 4);
  EXPECT_EQ(none.rows, 0u);
}

// The FEM's block with columns from two factorisations (its kept columns
// are solved again on a new one a few spheres a step), the tissue 25 %
// stiffer on the newer: neighbouring spheres under one face have nearly
// equal columns, and the rows' A is indefinite (checked below). load()
// scales the diagonal until A is semidefinite, and says so; the coupled
// solve converges to a force between the two factorisations' own. (On the
// tongue in real time PGS diverged on such an A: contact-contract.md.)
TEST(ContactSolver, BlockFromTwoFactorisationsIsMadeSemidefinite) {
  const std::size_t n = 16;
  const double local = 2e-4;   // m/N
  const double shared = 2e-3;  // m/N: the patch moving together
  test::SyntheticPatch older = test::make_patch(n, -0.001, local, shared);
  test::SyntheticPatch newer = test::make_patch(n, -0.001, 0.8 * local, 0.8 * shared);
  test::SyntheticPatch mixed = older;
  const std::size_t rows = 3 * n;
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < rows; ++c) {
      if ((c / 3) % 2 == 1) mixed.w[r * rows + c] = newer.w[r * rows + c];
    }
  }
  // The rows' A as the solver mirrors it (lower triangle): indefinite.
  Eigen::MatrixXd a(n, n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j <= i; ++j) {
      const double v =
          mixed.compliance().normal_compliance(i, mixed.rows[i].normal, j, mixed.rows[j].normal);
      a(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = v;
      a(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(i)) = v;
    }
  }
  ASSERT_LT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(a).eigenvalues()(0), -1e-5);

  const double k = 1000.0;
  const Eigen::Vector3d target(0, -0.002, 0);
  const auto resultant = [&](const test::SyntheticPatch& patch, SolverLoadReport& report) {
    ContactSolver solver(n);
    report = solver.load(patch.rows, patch.compliance());
    PgsSettings settings;
    settings.max_sweeps = 2000;
    const Eigen::Vector3d step = solver.solve_coupled(k, target, settings);
    EXPECT_TRUE(solver.last_report().converged) << "scale " << report.diagonal_scale;
    EXPECT_LE(step.norm(), target.norm() + 0.001 + 1e-9);
    return solver.resultant(RowKind::kTissue).norm();
  };
  SolverLoadReport report;
  const double f_old = resultant(older, report);
  EXPECT_EQ(report.diagonal_scale, 1.0);
  const double f_new = resultant(newer, report);
  EXPECT_EQ(report.diagonal_scale, 1.0);
  const double f_mixed = resultant(mixed, report);
  EXPECT_GT(report.diagonal_scale, 1.0);
  EXPECT_FALSE(report.indefinite);
  EXPECT_GT(f_mixed, 0.8 * f_old);
  EXPECT_LT(f_mixed, 1.2 * f_new);
}

TEST(ContactSolver, WarmStartConvergesInAFewSweeps) {
  // Weakly coupled so the cold solve converges within the budget.
  test::SyntheticPatch patch = test::make_patch(30, -0.002, 0.002, 0.0001);
  ContactSolver solver(32);
  PgsSettings settings;
  solver.load(patch.rows, patch.compliance());
  solver.solve_coupled(1000.0, Eigen::Vector3d(0, -0.001, 0), settings);
  const int cold = solver.last_report().sweeps;
  EXPECT_TRUE(solver.last_report().converged);
  solver.store_warm_start();
  solver.load(patch.rows, patch.compliance());
  solver.solve_coupled(1000.0, Eigen::Vector3d(0, -0.001, 0), settings);
  EXPECT_LE(solver.last_report().sweeps, 2);
  EXPECT_GT(cold, 2);
}

TEST(Coupling, IsClampedToTheDevice) {
  CouplingSettings settings;
  settings.stiffness_npm = 5000.0;
  settings.damping_nspm = 10.0;
  const EffectiveCoupling c = effective_coupling(settings, 1480.0, 0.001, Eigen::Vector3d::Zero(),
                                                 Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  EXPECT_EQ(c.stiffness_npm, 1480.0);
  EXPECT_EQ(c.damping_nspm, settings.max_damping_nspm);
}

// The local stiffness's factorisation on a full set of 64 rows that span
// three directions only (neighbouring spheres under one blade face), with
// float-rounding-sized indefiniteness: the dependent rows are dropped, and
// a right-hand side in the matrix's range is solved to rounding. With the
// pivot floored at 1e-12 instead, the multipliers of the rows after a
// floored one grew past the double range (the haptic service sent NaN
// stiffness about once a second while pressing).
TEST(DenseCholesky, DependentAndSlightlyIndefiniteRowsGiveAFiniteSolution) {
  const std::size_t n = 64;
  std::vector<Eigen::Vector3d> normals(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double t = 0.01 * static_cast<double>(i);
    normals[i] = Eigen::Vector3d(std::sin(t), 1.0, 0.3 * std::cos(3.0 * t)).normalized();
  }
  for (const double rounding : {0.0, 1e-9}) {
    // N N^T / k_c (rank 3), and W's float rounding: a symmetric part that
    // is not positive semidefinite.
    std::vector<double> s(n * n);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = 0; j < n; ++j) {
        s[i * n + j] = normals[i].dot(normals[j]) * 1e-3 +
                       rounding * std::cos(static_cast<double>(7 * i + 7 * j + i * j));
      }
    }
    std::vector<double> factor = s;
    EXPECT_GT(cholesky_in_place(factor.data(), n, n, 1e-12), 0);
    for (Eigen::Index c = 0; c < 3; ++c) {
      std::vector<double> x(n);
      for (std::size_t i = 0; i < n; ++i) x[i] = normals[i][c];
      const std::vector<double> b = x;
      cholesky_solve(factor.data(), n, n, x.data());
      Eigen::Vector3d k_column = Eigen::Vector3d::Zero();
      double residual = 0.0;
      for (std::size_t i = 0; i < n; ++i) {
        ASSERT_TRUE(std::isfinite(x[i])) << "rounding " << rounding << " row " << i;
        k_column += normals[i] * x[i];
        double sx = 0.0;
        for (std::size_t j = 0; j < n; ++j) sx += s[i * n + j] * x[j];
        residual = std::max(residual, std::abs(sx - b[i]));
      }
      ASSERT_TRUE(k_column.allFinite()) << "rounding " << rounding;
      // Without rounding the system is consistent and solved exactly on
      // its independent rows.
      if (rounding == 0.0) {
        EXPECT_LT(residual, 1e-9) << "column " << c;
      }
    }
  }
}

}  // namespace
}  // namespace fahr::contact
