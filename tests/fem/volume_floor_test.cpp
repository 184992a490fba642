// The volume floor (fem::VolumeFloor, and inside fem::ContactStep): a tet
// pressed below its share of the rest volume, or through itself, is opened
// back to the floor along its volume gradient, mass-weighted, fixed nodes
// untouched; a held tet's free node is recorded with its direction for the
// step's support spring; a tet above the floor is left exactly as it was;
// and a soft bar crushed by a large load keeps every tet above the floor
// through the step.
#include "fahr/fem/volume_floor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <vector>

#include "fahr/fem/assembly.h"
#include "fahr/fem/contact_step.h"
#include "fahr/fem/element_rest.h"
#include "fahr/fem/obstacle_support.h"
#include "scenes.h"

namespace fahr::fem {
namespace {

// One 10 mm right-angled tet, nodes 0..3.
struct OneTet {
  std::vector<Eigen::Vector3d> rest{{0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0}, {0, 0, 0.01}};
  std::vector<Tet> tets{{0, 1, 2, 3}};
  ElementRest element;
  OneTet() { EXPECT_TRUE(build_element_rest(rest, tets, element).empty()); }

  std::vector<double> positions_with_apex_at(double z_m) const {
    std::vector<double> x(12);
    for (std::size_t n = 0; n < 4; ++n) {
      for (std::size_t d = 0; d < 3; ++d) x[3 * n + d] = rest[n][static_cast<Eigen::Index>(d)];
    }
    x.back() = z_m;
    return x;
  }
};

double smallest_volume_ratio(const Body& body) {
  const ElementRest& rest = body.element_rest();
  double smallest = 1e300;
  for (std::size_t e = 0; e < rest.size(); ++e) {
    smallest =
        std::min(smallest, signed_volume(body.positions_m(), rest.tets[e]) / rest.volume_m3[e]);
  }
  return smallest;
}

TEST(VolumeFloor, ASquashedTetIsOpenedToItsFloor) {
  const OneTet tet;
  VolumeFloor floor(tet.element, {.ratio = 0.5, .max_sweeps = 8});
  std::vector<double> x = tet.positions_with_apex_at(0.001);  // a tenth of its volume
  const std::vector<double> inverse_mass(4, 1.0);
  const VolumeFloorReport report = floor.project(x, inverse_mass);
  EXPECT_EQ(report.below, 1);
  EXPECT_EQ(report.unresolved, 0);
  EXPECT_GE(signed_volume(x, tet.tets[0]), kVolumeFloorSlack * 0.5 * tet.element.volume_m3[0]);
}

TEST(VolumeFloor, AnInvertedTetIsTurnedBackAndFixedNodesStay) {
  const OneTet tet;
  VolumeFloor floor(tet.element, {.ratio = 0.3, .max_sweeps = 8});
  std::vector<double> x = tet.positions_with_apex_at(-0.004);  // through its base
  const std::vector<double> before = x;
  // Nodes 0 and 1 fixed: only 2 and 3 may open the tet.
  const std::vector<double> inverse_mass{0.0, 0.0, 1.0, 1.0};
  const VolumeFloorReport report = floor.project(x, inverse_mass);
  EXPECT_EQ(report.unresolved, 0);
  EXPECT_GE(signed_volume(x, tet.tets[0]), kVolumeFloorSlack * 0.3 * tet.element.volume_m3[0]);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(x[i], before[i]) << "a fixed node moved";
}

// The pass records each tet it moved and the direction it opened it along,
// for the step's support spring, until the next step begins: the gradient
// of the volume over the free nodes, of unit length. A held tet (three
// nodes fixed) opens by its fourth node alone, along the fixed face's
// normal.
TEST(VolumeFloor, AMovedTetRecordsTheDirectionItOpenedAlong) {
  const OneTet tet;
  VolumeFloor floor(tet.element, {.ratio = 0.5, .max_sweeps = 8});
  std::vector<double> x = tet.positions_with_apex_at(0.001);
  const VolumeFloorReport report = floor.project(x, std::vector<double>{0.0, 0.0, 0.0, 1.0});
  EXPECT_EQ(report.below, 1);
  ASSERT_TRUE(floor.moved(0));
  for (std::size_t n = 0; n < 3; ++n) EXPECT_EQ(floor.direction(0)[n].norm(), 0.0) << n;
  EXPECT_NEAR(floor.direction(0)[3].z(), 1.0, 1e-12);
  EXPECT_NEAR(floor.direction(0)[3].head<2>().norm(), 0.0, 1e-12);
  floor.begin_step();
  EXPECT_FALSE(floor.moved(0));

  // Two fixed nodes: the two free ones share the direction, each along its
  // own gradient.
  VolumeFloor two_fixed(tet.element, {.ratio = 0.5, .max_sweeps = 8});
  std::vector<double> y = tet.positions_with_apex_at(0.001);
  two_fixed.project(y, std::vector<double>{0.0, 0.0, 1.0, 1.0});
  EXPECT_GE(signed_volume(y, tet.tets[0]), kVolumeFloorSlack * 0.5 * tet.element.volume_m3[0]);
  ASSERT_TRUE(two_fixed.moved(0));
  const auto& d = two_fixed.direction(0);
  EXPECT_EQ(d[0].norm() + d[1].norm(), 0.0);
  EXPECT_NEAR(d[2].squaredNorm() + d[3].squaredNorm(), 1.0, 1e-12);
  EXPECT_GT(d[2].norm(), 0.0);
  EXPECT_GT(d[3].norm(), 0.0);
}

// A floored tet's spring in A (SystemAssembly::add_supports): k d d^T with
// k = ratio x the mean diagonal of its free nodes, so it stiffens the
// tet's volume direction d by exactly k and leaves a rigid translation
// (orthogonal to d: the volume gradients sum to zero) free.
TEST(VolumeFloor, ATetSpringStiffensItsVolumeAndNotATranslation) {
  const OneTet tet;
  VolumeFloor floor(tet.element, {.ratio = 0.5, .max_sweeps = 8});
  std::vector<double> x = tet.positions_with_apex_at(0.001);
  floor.project(x, std::vector<double>(4, 1.0));
  ASSERT_TRUE(floor.moved(0));
  const TetSupport support{0, floor.direction(0)};

  SystemAssembly assembly;
  assembly.build(4, tet.element, std::vector<std::uint8_t>(12, 0));
  const std::vector<double> mass{1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0};
  assembly.zero();
  assembly.add_mass(mass, 1.0);
  const Eigen::MatrixXd before = Eigen::MatrixXd(assembly.matrix());
  constexpr double kRatio = 100.0;
  assembly.add_supports({}, {&support, 1}, kRatio);
  const Eigen::MatrixXd added = Eigen::MatrixXd(assembly.matrix()) - before;

  Eigen::VectorXd d(12);
  for (std::size_t a = 0; a < 4; ++a)
    d.segment<3>(3 * static_cast<Eigen::Index>(a)) = support.direction[a];
  EXPECT_NEAR(d.norm(), 1.0, 1e-12);
  const double k = kRatio * 6.5;  // the mean of the diagonal 1..12
  EXPECT_NEAR(d.dot(added * d), k, 1e-9 * k);
  EXPECT_NEAR((added - k * d * d.transpose()).norm(), 0.0, 1e-9 * k);
  Eigen::VectorXd translation = Eigen::VectorXd::Zero(12);
  for (int a = 0; a < 4; ++a) translation[3 * a + 1] = 1.0;
  EXPECT_NEAR((added * translation).norm(), 0.0, 1e-9 * k);

  // With nodes 0-2 fixed it is a spring on node 3 alone, along the fixed
  // face's normal, and the fixed rows stay untouched.
  VolumeFloor held(tet.element, {.ratio = 0.5, .max_sweeps = 8});
  std::vector<double> y = tet.positions_with_apex_at(0.001);
  held.project(y, std::vector<double>{0.0, 0.0, 0.0, 1.0});
  const TetSupport on_face{0, held.direction(0)};
  std::vector<std::uint8_t> fixed(12, 1);
  for (int dof = 9; dof < 12; ++dof) fixed[static_cast<std::size_t>(dof)] = 0;
  SystemAssembly held_assembly;
  held_assembly.build(4, tet.element, fixed);
  held_assembly.zero();
  held_assembly.add_mass(mass, 1.0);
  const Eigen::MatrixXd held_before = Eigen::MatrixXd(held_assembly.matrix());
  held_assembly.add_supports({}, {&on_face, 1}, kRatio);
  const Eigen::MatrixXd held_added = Eigen::MatrixXd(held_assembly.matrix()) - held_before;
  const double k3 = kRatio * 11.0;  // node 3's diagonal 10, 11, 12
  EXPECT_NEAR(held_added(11, 11), k3, 1e-9 * k3);
  EXPECT_NEAR(held_added.norm(), k3, 1e-9 * k3);
}

// The step's record of floored tets (ObstacleSupport::update): a tet the
// floor moved is held from the next step on, kept while its free motion
// squeezes it, let go once its free motion opens it.
TEST(VolumeFloor, AFlooredTetIsHeldUntilItsFreeMotionOpensIt) {
  const OneTet tet;
  VolumeFloor floor(tet.element, {.ratio = 0.5, .max_sweeps = 8});
  ObstacleSupport supports(4, 1);
  std::vector<double> x = tet.positions_with_apex_at(0.001);
  floor.begin_step();
  floor.project(x, std::vector<double>(4, 1.0));
  const std::vector<double> start = x;
  EXPECT_TRUE(supports.update(nullptr, &floor, start, start));
  ASSERT_EQ(supports.tet_supports().size(), 1U);

  // The next step: the floor moves nothing, the free motion squeezes it
  // further (the apex down): still held, nothing changed.
  floor.begin_step();
  std::vector<double> squeezed = start;
  squeezed[11] -= 1e-5;
  EXPECT_FALSE(supports.update(nullptr, &floor, start, squeezed));
  EXPECT_EQ(supports.tet_supports().size(), 1U);
  // The apex up: it opens, and is let go.
  std::vector<double> opened = start;
  opened[11] += 1e-5;
  EXPECT_TRUE(supports.update(nullptr, &floor, start, opened));
  EXPECT_TRUE(supports.tet_supports().empty());
}

TEST(VolumeFloor, ATetAboveItsFloorIsLeftExactly) {
  const OneTet tet;
  VolumeFloor floor(tet.element, {.ratio = 0.5, .max_sweeps = 8});
  std::vector<double> x = tet.positions_with_apex_at(0.006);  // 60 % of its volume
  const std::vector<double> before = x;
  const std::vector<double> inverse_mass(4, 1.0);
  const VolumeFloorReport report = floor.project(x, inverse_mass);
  EXPECT_EQ(report.below, 0);
  EXPECT_EQ(x, before);
}

TEST(VolumeFloor, TheHeavierNodeMovesLess) {
  const OneTet tet;
  VolumeFloor floor(tet.element, {.ratio = 0.5, .max_sweeps = 1});
  std::vector<double> x = tet.positions_with_apex_at(0.001);
  const std::vector<double> before = x;
  // The apex ten times heavier than the base's nodes.
  const std::vector<double> inverse_mass{1.0, 1.0, 1.0, 0.1};
  floor.project(x, inverse_mass);
  const double apex = std::abs(x[11] - before[11]);
  const double base = std::abs(x[2] - before[2]);  // node 0 along z
  EXPECT_GT(base, 5.0 * apex);
}

// The 30 mm soft bar, fixed at x = 0, its free half's top pressed down with
// 3 N for 100 steps of 5 ms: the tongue's material cannot carry that, and
// the loaded layer is pushed through the bar.
struct CrushedBar {
  double smallest_ratio = 1.0;  // over every step's end, V / V0
  int steps_at_floor = 0;       // steps that ended with every tet at its floor
  int last_unresolved = 0;
};

CrushedBar crush_bar(double floor_ratio) {
  CrushedBar result;
  BodySettings settings;
  settings.sleep.enabled = false;
  settings.time_step = std::chrono::duration<double>(1.0 / 200.0);
  const BodyMesh mesh = test::bar_mesh(2);
  const std::vector<std::uint32_t> fixed = test::fixed_x0(mesh);
  auto body = test::make_body(settings, mesh, fixed);
  EXPECT_NE(body, nullptr);
  if (!body) return result;
  const SphereLinks links;
  ContactStepSettings step_settings;
  step_settings.volume_floor.ratio = floor_ratio;
  ContactStep step(*body, links, step_settings);
  const auto top = test::nodes_where(
      mesh, [](const Eigen::Vector3d& p) { return p.x() > 0.0149 && p.y() > 0.0099; });
  std::vector<double> push(3 * body->node_count(), 0.0);
  for (const std::uint32_t n : top) push[3 * n + 1] = -3.0 / static_cast<double>(top.size());
  double smallest = 1.0;
  for (int k = 0; k < 100; ++k) {
    const StepReport report = step.step(nullptr, push);
    EXPECT_TRUE(test::all_finite(*body));
    const double now = smallest_volume_ratio(*body);
    smallest = std::min(smallest, now);
    if (now >= kVolumeFloorSlack * floor_ratio) ++result.steps_at_floor;
    result.last_unresolved = report.projection.volume_floor_unresolved;
  }
  result.smallest_ratio = smallest;
  return result;
}

// Under a load the material cannot carry, the free step pushes about a
// hundred tets below the floor, some through themselves, every step; the
// pass opens them all again (with 8 full sweeps instead of 32 a few were
// left under it, one of them inverted, in some steps).
TEST(VolumeFloor, ACrushedBarKeepsItsTetsOpen) {
  const CrushedBar without = crush_bar(0.0);
  const CrushedBar with = crush_bar(0.5);
  EXPECT_LT(without.smallest_ratio, 0.0)
      << "the load must invert tets for the test to mean anything";
  EXPECT_GT(with.smallest_ratio, 0.0);
  EXPECT_EQ(with.steps_at_floor, 100);
  EXPECT_EQ(with.last_unresolved, 0);
}

// The floor's tets are held in A only while the floor is in force: the bar
// crushed as above, its tets held, then unloaded. Nothing presses it any
// more, so the floor's pass stops and every held tet is let go in the first
// unloaded step, whatever its free motion. Kept, the springs slowed the
// bar's return: 2 s after the load it lay 17.4 mm from a bar never
// loaded, 9 tets still held; let go, it lies under 1 um from it.
TEST(VolumeFloor, HeldTetsAreLetGoWhenNothingPressesTheBody) {
  BodySettings settings;
  settings.sleep.enabled = false;
  settings.time_step = std::chrono::duration<double>(1.0 / 200.0);
  const BodyMesh mesh = test::bar_mesh(2);
  const std::vector<std::uint32_t> fixed = test::fixed_x0(mesh);
  const SphereLinks links;
  ContactStepSettings step_settings;
  step_settings.volume_floor.ratio = 0.5;
  auto crushed = test::make_body(settings, mesh, fixed);
  auto unloaded = test::make_body(settings, mesh, fixed);
  ASSERT_NE(crushed, nullptr);
  ASSERT_NE(unloaded, nullptr);
  ContactStep crushed_step(*crushed, links, step_settings);
  ContactStep unloaded_step(*unloaded, links, step_settings);
  crushed_step.set_obstacles({}, ObstacleProjectionSettings{});
  unloaded_step.set_obstacles({}, ObstacleProjectionSettings{});
  const auto top = test::nodes_where(
      mesh, [](const Eigen::Vector3d& p) { return p.x() > 0.0149 && p.y() > 0.0099; });
  std::vector<double> push(3 * crushed->node_count(), 0.0);
  for (const std::uint32_t n : top) push[3 * n + 1] = -3.0 / static_cast<double>(top.size());
  const std::vector<double> none(push.size(), 0.0);
  std::size_t most_held = 0;
  for (int k = 0; k < 100; ++k) {
    crushed_step.step(nullptr, push);
    unloaded_step.step(nullptr, none);
    most_held = std::max(most_held, crushed->tet_support_count());
  }
  ASSERT_GT(most_held, 0U) << "the load must hold tets for the test to mean anything";
  crushed_step.step(nullptr, none);
  unloaded_step.step(nullptr, none);
  EXPECT_EQ(crushed->tet_support_count(), 0U);
  for (int k = 0; k < 400; ++k) {
    crushed_step.step(nullptr, none);
    unloaded_step.step(nullptr, none);
  }
  double apart = 0.0;  // the two bars, 2 s after the load
  for (std::uint32_t n = 0; n < crushed->node_count(); ++n) {
    apart = std::max(apart, (crushed->position(n) - unloaded->position(n)).norm());
  }
  EXPECT_LT(apart, 0.5e-3) << "2 s after the load the crushed bar is " << 1e3 * apart
                           << " mm from the bar never loaded";
  EXPECT_EQ(crushed->tet_support_count(), 0U);
}

}  // namespace
}  // namespace fahr::fem
