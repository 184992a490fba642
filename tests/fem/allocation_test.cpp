// No heap allocation inside step() after the first steps, for every solver
// configuration, with contacts; counted through a replaced operator new and
// SuiteSparse's allocation hooks.
#include <gtest/gtest.h>

#include <algorithm>

#include "allocation_counter.h"
#include "scenes.h"
#include "suitesparse_allocations.h"

namespace fahr::fem {
namespace {

struct Mode {
  const char* name;
  SolverSettings solver;
  bool refactorises;  // CHOLMOD mallocs inside refactorisation steps
};

std::vector<Mode> modes() {
  std::vector<Mode> list;
  SolverSettings s;
  s.refactor_period = 1;
  list.push_back({"cholmod every step", s, true});
  s.refactor_period = 0;
  list.push_back({"cholmod refactor on rotation", s, true});
  s.refactor_rotation_rad = 0.0;  // the modes below never refactorise
  list.push_back({"cholmod rest factor", s, false});
  s.kind = LinearSolver::kConjugateGradient;
  s.preconditioner = CgPreconditioner::kJacobi;
  list.push_back({"cg jacobi", s, false});
  s.preconditioner = CgPreconditioner::kLaggedCholesky;
  list.push_back({"cg lagged cholesky (rest)", s, false});
  s.refactor_period = 5;
  list.push_back({"cg lagged cholesky (period 5)", s, true});
  s.refactor_period = 0;
  s.cg_refresh_iterations = 1;
  list.push_back({"cg lagged cholesky (refreshed after 1 iteration)", s, true});
  s.cg_refresh_iterations = 0;
  s.warp_lagged_factor = true;
  list.push_back({"cg lagged cholesky (rest, warped)", s, false});
  return list;
}

TEST(Allocation, StepAllocatesNothing) {
  test::hook_suitesparse_allocations();
  const BodyMesh mesh = test::bar_mesh(2);
  // Every mode with the linear material, with compression stiffening, and
  // with the Stable Neo-Hookean material (stiffening 2: its Yeoh term).
  for (const double stiffening : {0.0, kTongueYeohC20OverC10, 2.0})
    for (const Mode& mode : modes()) {
      BodySettings settings;
      settings.solver = mode.solver;
      settings.material.yeoh_c20_over_c10 = std::min(stiffening, kTongueYeohC20OverC10);
      if (stiffening > 1.0) settings.material.model = MaterialModel::kStableNeoHookean;
      // The modes that must not refactorise keep a changed scale or F from
      // doing so.
      if (!mode.refactorises) {
        settings.solver.refactor_stiffening_change = 0.0;
        settings.solver.refactor_deformation_change = 0.0;
      }
      settings.sleep.enabled = false;
      auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
      ASSERT_NE(body, nullptr);
      SphereLinks links;
      const std::array<double, 4> w = {0.25, 0.25, 0.25, 0.25};
      ASSERT_EQ(links.add_sphere(mesh.tets.back(), w, 0.001), "");
      ContactSet set;
      Contact contact;
      contact.kind = ContactKind::kObstacle;
      contact.state = ContactState::kActive;
      contact.plane_point_m = Eigen::Vector3d(0, -0.002, 0);
      set.contacts.push_back(contact);
      body->set_external_force(static_cast<std::uint32_t>(mesh.nodes_m.size() - 1),
                               Eigen::Vector3d(0, 0.001, 0));
      for (int k = 0; k < 3; ++k) {
        set.state_step = body->step_index();
        body->step(&set, &links);
      }
      fahr::test::AllocationCounter counter;
      int refactorisations = 0;
      for (int k = 0; k < 20; ++k) {
        set.state_step = body->step_index();
        refactorisations += body->step(&set, &links).refactorised ? 1 : 0;
      }
      const long news = counter.count();
      const long suitesparse_allocs = counter.other_count();
      EXPECT_EQ(news, 0) << mode.name << ", stiffening " << stiffening;
      if (!mode.refactorises) {
        EXPECT_EQ(refactorisations, 0) << mode.name << ", stiffening " << stiffening;
        EXPECT_EQ(suitesparse_allocs, 0) << mode.name << ", stiffening " << stiffening;
      } else {
        // Reported, not asserted: CHOLMOD's numeric refactorisation mallocs its
        // permuted copy of A and supernodal workspace.
        std::printf(
            "[ info ] %s, stiffening %.2f: %d refactorisations, %ld CHOLMOD mallocs in 20 steps\n",
            mode.name, stiffening, refactorisations, suitesparse_allocs);
      }
    }
}

// The compliance block keeps each sphere's solved columns while the
// factorisation is unchanged: a changing set of spheres (as the blade
// slides) then solves only the new ones, in chunks whose CHOLMOD buffers are
// kept, and allocates nothing once each chunk size has been seen.
class ComplianceAllocation : public testing::TestWithParam<CholmodFactorKind> {};

// A sphere on each of the mesh's first `count` tets, equal weights.
SphereLinks spheres_on_first_tets(const BodyMesh& mesh, std::size_t count) {
  SphereLinks links;
  const std::array<double, 4> w = {0.25, 0.25, 0.25, 0.25};
  for (std::size_t s = 0; s < count; ++s) EXPECT_EQ(links.add_sphere(mesh.tets[s], w, 0.001), "");
  return links;
}

TEST_P(ComplianceAllocation, OfChangingSpheresAllocatesNothing) {
  test::hook_suitesparse_allocations();
  const BodyMesh mesh = test::bar_mesh(2);
  BodySettings settings;
  settings.solver.cholmod.factor = GetParam();
  settings.solver.refactor_period = 0;
  settings.solver.refactor_rotation_rad = 0.0;
  settings.max_compliance_spheres = 16;
  auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
  ASSERT_NE(body, nullptr);
  const SphereLinks links = spheres_on_first_tets(mesh, 40);
  std::vector<float> out(std::size_t{9} * 16 * 16);
  std::vector<std::uint32_t> spheres;
  const auto window = [&](std::uint32_t first, std::uint32_t count) {
    spheres.clear();
    for (std::uint32_t s = first; s < first + count; ++s) spheres.push_back(s);
    return body->compliance(spheres, links, out);
  };
  // Warm-up: every chunk size (8, 4, 2, 1 spheres) once.
  ASSERT_TRUE(window(0, 15));
  ASSERT_TRUE(window(20, 16));
  fahr::test::AllocationCounter counter;
  bool ok = true;
  for (std::uint32_t first = 1; first < 24; ++first) ok = window(first, 1 + first % 16) && ok;
  const long news = counter.count();
  const long suitesparse_allocs = counter.other_count();
  EXPECT_TRUE(ok);
  EXPECT_EQ(news, 0);
  EXPECT_EQ(suitesparse_allocs, 0);
}

// A background factorisation that brings the block along (the spheres of
// the last request solved on its thread, adopted at the install): the
// step's thread allocates nothing for it, in the steps that begin, install
// and adopt, while the spheres change.
TEST(Allocation, TheBlockBroughtByTheFactorisationsThreadAllocatesNothingOnTheStep) {
  const BodyMesh mesh = test::bar_mesh(2);
  const SphereLinks links = spheres_on_first_tets(mesh, 40);
  std::vector<std::uint32_t> spheres;
  spheres.reserve(16);
  std::vector<float> out(std::size_t{9} * 16 * 16);
  BodySettings settings;
  settings.max_compliance_spheres = 16;
  settings.time_step = std::chrono::milliseconds(10);
  settings.solver.refactor_period = 3;
  settings.solver.background_factor_latency_s = 0.02;  // two 10 ms steps
  settings.solver.cholmod.factor = CholmodFactorKind::kSupernodal;
  settings.sleep.enabled = false;
  auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
  ASSERT_NE(body, nullptr);
  int refactorisations = 0;
  const auto step = [&](std::uint32_t first) {
    spheres.clear();
    for (std::uint32_t s = first; s < first + 1 + first % 16; ++s) spheres.push_back(s);
    const bool ok = body->compliance(spheres, links, out);
    refactorisations += body->step().refactorised ? 1 : 0;
    return ok;
  };
  for (std::uint32_t first = 0; first < 24; ++first) ASSERT_TRUE(step(first));
  const std::uint64_t adopted_before = body->compliance_refreshes_adopted();
  refactorisations = 0;
  fahr::test::AllocationCounter counter;
  bool ok = true;
  for (std::uint32_t first = 0; first < 24; ++first) ok = step(first) && ok;
  const long news = counter.count();
  EXPECT_TRUE(ok);
  EXPECT_EQ(news, 0);
  EXPECT_GT(refactorisations, 3);
  EXPECT_GT(body->compliance_refreshes_adopted(), adopted_before);
}

// Full solves (simplicial) and half solves on the supernodes reached.
INSTANTIATE_TEST_SUITE_P(Allocation, ComplianceAllocation,
                         testing::Values(CholmodFactorKind::kSimplicial,
                                         CholmodFactorKind::kSupernodal));

}  // namespace
}  // namespace fahr::fem
