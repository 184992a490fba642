// Algorithm 1 projection: mass-weighted spread, frozen and active
// constraints, repeated, dropped and stale ContactSets.
#include "fahr/fem/projection.h"

#include <gtest/gtest.h>

#include "scenes.h"

namespace fahr::fem {
namespace {

// A sphere tied to the four nodes of tet `e` with equal weights.
SphereLinks links_for_tets(const BodyMesh& mesh, std::initializer_list<std::size_t> tets,
                           double radius_m) {
  SphereLinks links;
  for (const std::size_t e : tets) {
    const std::array<double, 4> w = {0.25, 0.25, 0.25, 0.25};
    EXPECT_EQ(links.add_sphere(mesh.tets[e], w, radius_m), "");
  }
  return links;
}

// One sphere on the unit tet's four nodes with unequal weights; node 0 is
// fixed (inverse mass 0), node 3 ten times heavier than node 2.
struct OneSphere {
  SphereLinks links;
  std::vector<double> positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  const std::vector<double> start = positions;
  const std::vector<double> inverse_mass = {0.0, 1.0 / 0.002, 1.0 / 0.001, 1.0 / 0.01};
  const Eigen::Vector3d dc{0.003, -0.002, 0.0015};
  OneSphere() {
    const std::array<std::uint32_t, 4> nodes = {0, 1, 2, 3};
    const std::array<double, 4> weights = {0.1, 0.2, 0.3, 0.4};
    EXPECT_EQ(links.add_sphere(nodes, weights, 0.001), "");
  }
};

TEST(Projection, CentreMovesExactlyByCorrectionAndHeavyNodesMoveLess) {
  OneSphere one;
  auto& [links, positions, start, inverse_mass, dc] = one;
  const Eigen::Vector3d before = links.centre(0, positions.data());
  ASSERT_TRUE(move_sphere_centre(0, links, inverse_mass, dc, positions));
  const Eigen::Vector3d after = links.centre(0, positions.data());
  EXPECT_NEAR((after - before - dc).norm(), 0.0, 1e-15);
  auto moved = [&](int node) {
    return Eigen::Vector3d(positions[3 * node] - start[3 * node],
                           positions[3 * node + 1] - start[3 * node + 1],
                           positions[3 * node + 2] - start[3 * node + 2])
        .norm();
  };
  EXPECT_EQ(moved(0), 0.0);
  EXPECT_LT(moved(3), moved(2));  // heavier (and larger weight) still moves less
  // All nodes fixed: nothing can move, reported.
  const std::vector<double> all_fixed(4, 0.0);
  EXPECT_FALSE(move_sphere_centre(0, links, all_fixed, dc, positions));
}

// The paper's c' = c: a frozen sphere stays where the step found it, whatever hold centre the set
// carries, so the bar's tip, frozen mid-fall, stays put under gravity.
TEST(Projection, FrozenSphereStaysWhereTheStepStarted) {
  const BodyMesh mesh = test::bar_mesh(2);
  BodySettings settings;
  auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
  ASSERT_NE(body, nullptr);
  const SphereLinks links = links_for_tets(mesh, {mesh.tets.size() - 1}, 0.002);
  for (int k = 0; k < 20; ++k) body->step();  // falling
  const Eigen::Vector3d where = links.centre(0, body->positions_m().data());
  ContactSet set;
  Contact frozen;
  frozen.sphere_id = 0;
  frozen.state = ContactState::kFrozen;
  frozen.hold_centre_m = where + Eigen::Vector3d(0, 0.005, 0);  // ignored
  set.contacts.push_back(frozen);
  for (int k = 0; k < 100; ++k) {
    set.state_step = body->step_index();
    body->step(&set, &links);
    ASSERT_NEAR((links.centre(0, body->positions_m().data()) - where).norm(), 0.0, 1e-12)
        << "step " << k;
  }
}

// Holds whose hold centres contradict each other: two spheres over the same
// nodes, their hold centres 6 mm apart (pulled to such targets in turn, the
// neonatal overshoot's nodes moved 153 mm in one step). Held where the step
// started, the nodes do not move.
TEST(Projection, ContradictoryHoldsDoNotDragTheNodes) {
  const BodyMesh mesh = test::bar_mesh(2);
  const std::size_t tip_tet = mesh.tets.size() - 1;
  {
    BodySettings settings;
    settings.gravity_m_per_s2 = Eigen::Vector3d::Zero();
    auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
    ASSERT_NE(body, nullptr);
    SphereLinks links;
    const std::array<double, 4> a = {0.7, 0.1, 0.1, 0.1};
    const std::array<double, 4> b = {0.1, 0.1, 0.1, 0.7};
    ASSERT_EQ(links.add_sphere(mesh.tets[tip_tet], a, 0.001), "");
    ASSERT_EQ(links.add_sphere(mesh.tets[tip_tet], b, 0.001), "");
    const std::vector<double> rest(body->positions_m().begin(), body->positions_m().end());
    ContactSet set;
    for (std::uint32_t s = 0; s < 2; ++s) {
      Contact frozen;
      frozen.sphere_id = s;
      frozen.state = ContactState::kFrozen;
      frozen.hold_centre_m =
          links.centre(s, rest.data()) + Eigen::Vector3d(0, s == 0 ? 0.003 : -0.003, 0);
      set.contacts.push_back(frozen);
    }
    set.state_step = body->step_index();
    body->step(&set, &links);
    double largest = 0.0;
    for (std::size_t i = 0; i < rest.size(); ++i)
      largest = std::max(largest, std::abs(body->positions_m()[i] - rest[i]));
    EXPECT_LT(largest, 1e-9);
  }
}

TEST(Projection, ActiveConstraintLeavesNoPenetration) {
  // The bar sags under gravity onto an obstacle plane y = -4 mm below it.
  const BodyMesh mesh = test::bar_mesh(2);
  BodySettings settings;
  auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
  ASSERT_NE(body, nullptr);
  // Spheres on the last few tets along the bottom (all tets of the last cells).
  SphereLinks links;
  std::vector<std::size_t> spheres_tets;
  for (std::size_t e = 0; e < mesh.tets.size(); ++e) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const auto n : mesh.tets[e]) c += 0.25 * mesh.nodes_m[n];
    if (c.x() > 0.015) {
      const std::array<double, 4> w = {0.25, 0.25, 0.25, 0.25};
      ASSERT_EQ(links.add_sphere(mesh.tets[e], w, 0.001), "");
    }
  }
  ContactSet set;
  for (std::uint32_t s = 0; s < links.size(); ++s) {
    Contact c;
    c.sphere_id = s;
    c.kind = ContactKind::kObstacle;
    c.state = ContactState::kActive;
    c.plane_point_m = Eigen::Vector3d(0, -0.004, 0);
    c.normal = Eigen::Vector3d(0, 1, 0);
    set.contacts.push_back(c);
  }
  double worst = 0.0;
  int touching_steps = 0;
  for (int k = 0; k < 300; ++k) {
    set.state_step = body->step_index();
    const StepReport report = body->step(&set, &links);
    ASSERT_TRUE(report.projection.converged);
    for (std::uint32_t s = 0; s < links.size(); ++s) {
      const double gap =
          links.centre(s, body->positions_m().data()).y() + 0.004 - links.radius_m(s);
      worst = std::min(worst, gap);
    }
    if (report.projection.last_correction_m > 0.0 || report.projection.sweeps > 1) ++touching_steps;
  }
  EXPECT_GT(touching_steps, 10);  // the plane was really reached
  EXPECT_GE(worst, -settings.projection.tolerance_m);
}

// Runs 60 steps of a tool contact lifting the tip 3 mm; `schedule(k)` says
// whether the set arrives at step k (false: dropped); a repeated set keeps
// its old state_step, as a reliable keep-last reader would hand it over again.
std::vector<double> run_schedule(bool (*schedule)(int), bool repeat_old) {
  const BodyMesh mesh = test::bar_mesh(2);
  BodySettings settings;
  auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
  const SphereLinks links = links_for_tets(mesh, {mesh.tets.size() - 1}, 0.002);
  ContactSet set;
  Contact lift;
  lift.state = ContactState::kActive;
  lift.normal = Eigen::Vector3d::UnitY();
  // (c - q) . n >= r: the centre at least 3 mm above where it starts.
  lift.plane_point_m = links.centre(0, body->positions_m().data()) +
                       Eigen::Vector3d(0, 0.003 - links.radius_m(0), 0);
  set.contacts.push_back(lift);
  for (int k = 0; k < 60; ++k) {
    const bool arrives = schedule(k);
    if (arrives || !repeat_old) set.state_step = body->step_index();
    body->step(arrives || repeat_old ? &set : nullptr, &links);
  }
  return {body->positions_m().begin(), body->positions_m().end()};
}

TEST(Projection, RepeatedSetChangesNothing) {
  const auto every = run_schedule([](int) { return true; }, false);
  // Every other sample lost, the reader repeating the newest one it has.
  const auto repeated = run_schedule([](int k) { return k % 2 == 0; }, true);
  for (std::size_t i = 0; i < every.size(); ++i) ASSERT_EQ(every[i], repeated[i]);
}

TEST(Projection, DroppedSetOnlyAffectsItsOwnStep) {
  const auto every = run_schedule([](int) { return true; }, false);
  const auto dropped = run_schedule([](int k) { return k != 30; }, false);
  // The hold is re-imposed the next step; what remains 29 steps later is the
  // damped echo of one unconstrained step, well below 1 % of the hold offset.
  double largest = 0.0;
  for (std::size_t i = 0; i < every.size(); ++i)
    largest = std::max(largest, std::abs(every[i] - dropped[i]));
  EXPECT_LT(largest, 3e-5);
}

TEST(Projection, StaleSetsAreIgnoredAndCounted) {
  const BodyMesh mesh = test::bar_mesh(2);
  BodySettings settings;
  settings.max_contact_age_steps = 3;
  auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
  const SphereLinks links = links_for_tets(mesh, {mesh.tets.size() - 1}, 0.002);
  ContactSet set;
  Contact frozen;
  frozen.state = ContactState::kFrozen;
  set.contacts.push_back(frozen);
  for (int k = 0; k < 10; ++k) body->step();
  set.state_step = body->step_index() - 4;  // too old
  StepReport report = body->step(&set, &links);
  EXPECT_TRUE(report.contacts_stale);
  EXPECT_FALSE(report.contacts_applied);
  set.state_step = body->step_index() + 5;  // from the future
  report = body->step(&set, &links);
  EXPECT_TRUE(report.contacts_stale);
  EXPECT_EQ(body->stale_sets_ignored(), 2u);
  set.state_step = body->step_index() - 3;  // old but within the age
  set.contacts[0].hold_centre_m = links.centre(0, body->positions_m().data());
  report = body->step(&set, &links);
  EXPECT_TRUE(report.contacts_applied);
  // Computed on a state long past but just arrived (the sender's snapshot
  // lagged): its planes are where the tool is, so it is applied; once it
  // has been the newest for longer than the age (the sender silent), not.
  set.state_step = body->step_index() - 8;
  set.received_step = body->step_index();
  report = body->step(&set, &links);
  EXPECT_TRUE(report.contacts_applied);
  for (int k = 0; k < 3; ++k) EXPECT_TRUE(body->step(&set, &links).contacts_applied);
  report = body->step(&set, &links);
  EXPECT_TRUE(report.contacts_stale);
  EXPECT_EQ(body->stale_sets_ignored(), 3u);
  set.received_step = 0;
  // Links that reference nodes beyond this mesh are refused, not followed.
  SphereLinks foreign;
  const std::array<std::uint32_t, 1> far_node = {static_cast<std::uint32_t>(mesh.nodes_m.size())};
  const std::array<double, 1> one = {1.0};
  ASSERT_EQ(foreign.add_sphere(far_node, one, 0.001), "");
  set.state_step = body->step_index();
  report = body->step(&set, &foreign);
  EXPECT_TRUE(report.contacts_invalid);
  EXPECT_EQ(body->invalid_sets_ignored(), 1u);
  // An unknown sphere id is skipped and reported.
  set.contacts[0].sphere_id = 7;
  report = body->step(&set, &links);
  EXPECT_EQ(report.projection.unknown_spheres, 1);
}

}  // namespace
}  // namespace fahr::fem
