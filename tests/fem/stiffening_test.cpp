// Compression stiffening: the Yeoh scale, its place in the force and in A, a
// punched bar that no longer inverts, and off meaning the linear material
// bit for bit.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "fahr/fem/compression_stiffening.h"
#include "scenes.h"

namespace fahr::fem {
namespace {

TEST(Stiffening, ScaleIsOneAtRestInRotationAndInUniformScaling) {
  const double ratio = kTongueYeohC20OverC10;
  EXPECT_EQ(stiffening_scale(Eigen::Matrix3d::Identity(), ratio), 1.0);
  for (const double degrees : {10.0, 90.0, 179.0}) {
    const Eigen::Matrix3d r =
        Eigen::AngleAxisd(degrees * M_PI / 180.0, Eigen::Vector3d(0.3, -0.8, 0.52).normalized())
            .toRotationMatrix();
    EXPECT_NEAR(stiffening_scale(r, ratio), 1.0, 1e-12) << degrees << " degrees";
  }
  // I1bar is isochoric: a uniform volume change is not stiffened.
  EXPECT_NEAR(stiffening_scale(0.6 * Eigen::Matrix3d::Identity(), ratio), 1.0, 1e-12);
  // Off: exactly 1 whatever the deformation.
  EXPECT_EQ(stiffening_scale(Eigen::Vector3d(1.0, 1.0, 0.1).asDiagonal(), 0.0), 1.0);
}

TEST(Stiffening, CompressedElementGetsTheYeohRatioUpToTheCap) {
  const double ratio = kTongueYeohC20OverC10;
  // F = diag(1.1, 1.1, 0.6): I1bar = J^(-2/3) tr(F^T F) by hand.
  const double j = 1.1 * 1.1 * 0.6;
  const double i1_bar = (1.1 * 1.1 + 1.1 * 1.1 + 0.6 * 0.6) / std::pow(j, 2.0 / 3.0);
  const double expected = 1.0 + 2.0 * ratio * (i1_bar - 3.0);
  EXPECT_GT(expected, 1.1);
  EXPECT_NEAR(stiffening_scale(Eigen::Vector3d(1.1, 1.1, 0.6).asDiagonal(), ratio), expected,
              1e-12);
  // Flattening grows it without bound until the cap; inverted gets the cap.
  double previous = 1.0;
  for (const double thickness : {0.5, 0.2, 0.1, 0.05, 0.02}) {
    const double s = stiffening_scale(Eigen::Vector3d(1.0, 1.0, thickness).asDiagonal(), ratio);
    EXPECT_GT(s, previous) << thickness;
    previous = s;
  }
  EXPECT_EQ(stiffening_scale(Eigen::Vector3d(1.0, 1.0, 1e-4).asDiagonal(), ratio),
            kMaxStiffeningScale);
  EXPECT_EQ(stiffening_scale(Eigen::Vector3d(1.0, 1.0, -0.5).asDiagonal(), ratio),
            kMaxStiffeningScale);
}

// One tet, compressed along z: the stiffened body's elastic force and the
// stiffness part of its A are the linear body's times s.
TEST(Stiffening, ScalesTheElementForceAndItsBlockOfA) {
  const std::vector<Eigen::Vector3d> nodes = {
      {0.0, 0.0, 0.0}, {0.01, 0.0, 0.0}, {0.0, 0.01, 0.0}, {0.0, 0.0, 0.01}};
  const std::vector<Tet> tets = {{0, 1, 2, 3}};
  BodySettings linear;
  linear.gravity_m_per_s2.setZero();
  BodySettings stiff = linear;
  stiff.material.yeoh_c20_over_c10 = kTongueYeohC20OverC10;
  auto a = std::move(Body::create(linear, nodes, tets, {}).body);
  auto b = std::move(Body::create(stiff, nodes, tets, {}).body);
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  const Eigen::Vector3d squeezed(0.0, 0.0, 0.004);
  a->set_node_position(3, squeezed);
  b->set_node_position(3, squeezed);
  // The tet's rest edges are the unit axes times 0.01: F = diag(1, 1, 0.4).
  const double s =
      stiffening_scale(Eigen::Vector3d(1.0, 1.0, 0.4).asDiagonal(), kTongueYeohC20OverC10);
  ASSERT_GT(s, 1.5);
  std::vector<double> fa(12), fb(12);
  a->elastic_forces(fa);
  b->elastic_forces(fb);
  for (std::size_t k = 0; k < 12; ++k)
    EXPECT_NEAR(fb[k], s * fa[k], 1e-12 * std::abs(s * fa[k]) + 1e-15) << k;
  // A step assembles A at the start-of-step state (refactor_period 1); the
  // mass is diagonal, so every off-diagonal entry is stiffness alone.
  a->step();
  b->step();
  const SparseMatrix& ma = a->system_matrix();
  const SparseMatrix& mb = b->system_matrix();
  int compared = 0;
  for (int col = 0; col < ma.outerSize(); ++col) {
    for (SparseMatrix::InnerIterator ia(ma, col), ib(mb, col); ia; ++ia, ++ib) {
      if (ia.row() == ia.col() || std::abs(ia.value()) < 1e-12) continue;
      EXPECT_NEAR(ib.value(), s * ia.value(), 1e-9 * std::abs(s * ia.value()));
      ++compared;
    }
  }
  EXPECT_GT(compared, 20);
}

// A 30 x 10 x 10 mm bar on its y = 0 face, a node in the middle of its top
// pushed down far (as a blade's rim presses the tongue): the linear
// material lets the node punch through the elements below it, the
// stiffened one does not.
int most_inverted_when_punched(double c20_over_c10) {
  const BodyMesh mesh = test::bar_mesh(2);
  BodySettings settings;
  settings.time_step = std::chrono::milliseconds(5);
  settings.gravity_m_per_s2.setZero();
  settings.material.yeoh_c20_over_c10 = c20_over_c10;
  const auto floor = test::nodes_where(mesh, [](const Eigen::Vector3d& p) { return p.y() < 1e-9; });
  auto body = test::make_body(settings, mesh, floor);
  if (body == nullptr) return -1;
  std::uint32_t punched = 0;
  const Eigen::Vector3d centre(0.015, 0.01, 0.005);
  for (std::uint32_t n = 0; n < body->node_count(); ++n) {
    if ((mesh.nodes_m[n] - centre).norm() < (mesh.nodes_m[punched] - centre).norm()) punched = n;
  }
  // 1 N ramped over 1 s and held: 20 times the load that presses the node
  // 1 mm into the linear bar.
  constexpr double kLoadN = 1.0;
  int most = 0;
  for (int k = 0; k < 400; ++k) {
    const double ramp = std::min(1.0, (k + 1) / 200.0);
    body->set_external_force(punched, Eigen::Vector3d(0.0, -ramp * kLoadN, 0.0));
    const StepReport report = body->step();
    if (report.solve_failed || !test::all_finite(*body)) return -1;
    most = std::max(most, report.inverted_elements);
  }
  std::printf(
      "[ info ] punched bar, C20/C10 %.2f: %d tets inverted at most, the node %.1f mm down\n",
      c20_over_c10, most, 1e3 * (mesh.nodes_m[punched].y() - body->position(punched).y()));
  return most;
}

TEST(Stiffening, APunchedBarDoesNotInvertWhereTheLinearMaterialDoes) {
  EXPECT_GT(most_inverted_when_punched(0.0), 0);
  EXPECT_EQ(most_inverted_when_punched(kTongueYeohC20OverC10), 0);
}

std::uint64_t hash_positions(std::span<const double> positions) {
  std::uint64_t hash = 1469598103934665603ull;  // FNV-1a
  for (const double x : positions) {
    unsigned char bytes[sizeof(double)];
    std::memcpy(bytes, &x, sizeof(double));
    for (const unsigned char b : bytes) hash = (hash ^ b) * 1099511628211ull;
  }
  return hash;
}

// Off (C20/C10 = 0, the default) must be the FEM as it was before
// stiffening existed, bit for bit: the hashes below were recorded with that
// FEM (commit 9a0b2f1, Release, this toolchain) on this very run, with the
// exact step, the lagged factor with its rotation trigger and Jacobi CG. A
// deliberate change of the linear path changes them; then record them
// again. The CHOLMOD runs hold with one BLAS thread, as ctest runs them
// (tests/fem/CMakeLists.txt; a multithreaded OpenBLAS sums the supernodes
// in another order); the CG run, which uses no BLAS, holds either way.
struct RecordedRun {
  const char* name;
  SolverSettings solver;
  std::uint64_t hash;
};

std::vector<RecordedRun> recorded_runs() {
  std::vector<RecordedRun> runs;
  SolverSettings exact;
  runs.push_back({"exact", exact, 0xbf4d4f046d196363ull});
  SolverSettings lagged;
  lagged.refactor_period = 0;
  lagged.refactor_rotation_rad = 0.1;
  runs.push_back({"lagged", lagged, 0xc0a94f7ed40be6a3ull});
  SolverSettings cg;
  cg.kind = LinearSolver::kConjugateGradient;
  cg.preconditioner = CgPreconditioner::kJacobi;
  cg.refactor_period = 0;
  cg.refactor_rotation_rad = 0.0;
  runs.push_back({"jacobi cg", cg, 0x6f573592979a1424ull});
  return runs;
}

TEST(Stiffening, OffIsTheLinearMaterialBitForBit) {
  const BodyMesh mesh = test::bar_mesh(2);
  const auto fixed = test::fixed_x0(mesh);
  std::uint32_t tip = 0;
  for (std::size_t i = 0; i < mesh.nodes_m.size(); ++i) {
    if (mesh.nodes_m[i].x() > 0.0299 && mesh.nodes_m[i].y() > 0.0099) {
      tip = static_cast<std::uint32_t>(i);
    }
  }
  for (const RecordedRun& run : recorded_runs()) {
    BodySettings settings;
    settings.time_step = std::chrono::milliseconds(5);
    settings.solver = run.solver;
    ASSERT_EQ(settings.material.yeoh_c20_over_c10, 0.0);
    auto body = test::make_body(settings, mesh, fixed);
    ASSERT_NE(body, nullptr);
    body->set_external_force(tip, Eigen::Vector3d(0.0, -0.5, 0.2));
    for (int k = 0; k < 100; ++k) body->step();
    body->clear_external_forces();
    for (int k = 0; k < 100; ++k) body->step();
    EXPECT_EQ(hash_positions(body->positions_m()), run.hash) << run.name;
  }
}

// A stiffening element refreshes a lagged factorisation as a turning one
// does; without stiffening the trigger never fires.
TEST(Stiffening, AChangedScaleRefreshesALaggedFactor) {
  const BodyMesh mesh = test::bar_mesh(2);
  const auto fixed = test::nodes_where(mesh, [](const Eigen::Vector3d& p) { return p.y() < 1e-9; });
  const auto top =
      test::nodes_where(mesh, [](const Eigen::Vector3d& p) { return p.y() > 0.01 - 1e-9; });
  std::uint64_t refreshes[2] = {0, 0};
  for (const double change : {0.0, 0.1}) {
    BodySettings settings;
    settings.time_step = std::chrono::milliseconds(5);
    settings.gravity_m_per_s2.setZero();
    settings.material.yeoh_c20_over_c10 = kTongueYeohC20OverC10;
    settings.solver.refactor_period = 0;
    settings.solver.refactor_rotation_rad = 0.0;  // only the scale can trigger
    settings.solver.refactor_stiffening_change = change;
    auto body = test::make_body(settings, mesh, fixed);
    ASSERT_NE(body, nullptr);
    for (const std::uint32_t n : top) body->set_external_force(n, Eigen::Vector3d(0.0, -0.2, 0.0));
    const std::uint64_t before = body->factorisations();
    for (int k = 0; k < 100; ++k) body->step();
    refreshes[change > 0.0 ? 1 : 0] = body->factorisations() - before;
  }
  EXPECT_EQ(refreshes[0], 0u);
  EXPECT_GT(refreshes[1], 0u);
}

TEST(Stiffening, BadRatioIsRejected) {
  const BodyMesh mesh = test::bar_mesh(1);
  BodySettings settings;
  settings.material.yeoh_c20_over_c10 = -0.1;
  BodyOrError made = Body::create(settings, mesh.nodes_m, mesh.tets, test::fixed_x0(mesh));
  EXPECT_EQ(made.body, nullptr);
  EXPECT_NE(made.error.find("yeoh_c20_over_c10"), std::string::npos);
  settings.material.yeoh_c20_over_c10 = std::nan("");
  EXPECT_EQ(Body::create(settings, mesh.nodes_m, mesh.tets, test::fixed_x0(mesh)).body, nullptr);
}

}  // namespace
}  // namespace fahr::fem
