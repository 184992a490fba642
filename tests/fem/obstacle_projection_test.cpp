// The FEM's own non-penetration of static rigid anatomy (ObstacleProjection
// inside fem::ContactStep): a soft bar pressed onto a rigid floor by a tool
// that would push it through never has a node deeper than the margin, fixed
// nodes never move, the moves are carried as velocity (the bar comes to
// rest on the floor), a node driven into or through a thin plate is put
// back on its own side, bad input does not spread, far nodes are not
// sampled every step, and a step allocates nothing once warmed.
#include "fahr/fem/obstacle_projection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#ifndef FAHR_SANITIZE_BUILD
#include "allocation_counter.h"
#include "suitesparse_allocations.h"
#endif
#include "fahr/fem/contact_step.h"
#include "scenes.h"

namespace fahr::fem {
namespace {

constexpr double kMargin = 0.2e-3;  // ObstacleProjectionSettings' default, m
// The half-space is exact, so a node sits at the margin to rounding; the
// step's own tolerance is 1 um.
constexpr double kTolerance = 1.01e-6;

// The rigid floor y < level (its outward normal +y): an exact signed distance.
class Floor final : public ObstacleField {
 public:
  explicit Floor(double level_m) : level_m_(level_m) {}
  ObstacleSample sample(const Eigen::Vector3d& p) const noexcept override {
    ++samples;
    return {p.y() - level_m_, Eigen::Vector3d::UnitY()};
  }
  mutable int samples = 0;

 private:
  double level_m_;
};

// A bone plate |y - centre| < half thickness: its nearest surface flips at
// the mid-plane.
class Plate final : public ObstacleField {
 public:
  Plate(double centre_m, double half_thickness_m)
      : centre_m_(centre_m), half_m_(half_thickness_m) {}
  ObstacleSample sample(const Eigen::Vector3d& p) const noexcept override {
    const double side = p.y() >= centre_m_ ? 1.0 : -1.0;
    return {std::abs(p.y() - centre_m_) - half_m_, Eigen::Vector3d(0, side, 0)};
  }

 private:
  double centre_m_, half_m_;
};

// A field that cannot answer: the projection must leave the nodes alone.
class Broken final : public ObstacleField {
 public:
  ObstacleSample sample(const Eigen::Vector3d&) const noexcept override {
    return {std::numeric_limits<double>::quiet_NaN(), Eigen::Vector3d::UnitY()};
  }
};

BodySettings tongue_like() {
  BodySettings s;  // neonatal tongue material (E 10 kPa, nu 0.45)
  s.sleep.enabled = false;
  s.time_step = std::chrono::duration<double>(1.0 / 200.0);  // the FEM service's rate
  return s;
}

// The 30 x 10 x 10 mm bar, its x = 0 face fixed; one sphere (weight 1,
// radius 0) on each top node of the free half, which the tool presses.
struct PressedBar {
  BodyMesh mesh = test::bar_mesh(2);
  std::vector<std::uint32_t> fixed = test::fixed_x0(mesh);
  std::vector<std::uint32_t> top;
  SphereLinks links;
  PressedBar() {
    top = test::nodes_where(
        mesh, [](const Eigen::Vector3d& p) { return p.x() > 0.0149 && p.y() > 0.0099; });
    const double w = 1.0;
    for (const std::uint32_t n : top) EXPECT_EQ(links.add_sphere({&n, 1}, {&w, 1}, 0.0), "");
  }
  // The tool holds every top node `depth_m` below its rest height (through
  // the bar and the floor) and pushes the first with `force_n` on top.
  ContactSet press(const Body& body, double depth_m, double force_n) const {
    ContactSet set;
    set.state_step = body.step_index();
    for (std::size_t s = 0; s < top.size(); ++s) {
      Contact c;
      c.sphere_id = static_cast<std::uint32_t>(s);
      c.state = ContactState::kFrozen;
      c.normal = Eigen::Vector3d(0, -1, 0);
      c.hold_centre_m = body.rest_position(top[s]) - Eigen::Vector3d(0, depth_m, 0);
      set.contacts.push_back(c);
    }
    Contact push;
    push.kind = ContactKind::kForceOnly;
    push.state = ContactState::kActive;
    push.normal = Eigen::Vector3d(0, -1, 0);
    push.force_n = force_n;
    set.contacts.push_back(push);
    return set;
  }
};

// The pressed bar stepped with a floor 1 mm below it as its anatomy.
struct BarOverFloor {
  PressedBar bar;
  std::unique_ptr<Body> body;
  Floor floor{-1e-3};
  std::unique_ptr<ContactStep> step;
  explicit BarOverFloor(const BodySettings& settings)
      : body(test::make_body(settings, bar.mesh, bar.fixed)) {
    if (!body) return;
    step = std::make_unique<ContactStep>(*body, bar.links);
    const ObstacleField* fields[] = {&floor};
    step->set_obstacles(fields);
  }
};

TEST(ObstacleProjection, APressedBodyNeverGoesDeeperThanTheMargin) {
  PressedBar bar;
  auto body = test::make_body(tongue_like(), bar.mesh, bar.fixed);
  ASSERT_TRUE(body);
  const Floor floor(-1e-3);  // 1 mm below the bar
  const ObstacleField* fields[] = {&floor};
  ContactStep step(*body, bar.links);
  step.set_obstacles(fields);
  int deepest_step = 0;
  double deepest_free = 0.0;
  for (int k = 0; k < 300;
       ++k) {  // 1.5 s: pressed 15 mm through the bar and 14 mm into the floor, and 1 N
    const ContactSet set = bar.press(*body, 0.015, 1.0);
    const StepReport report = step.step(&set);
    ASSERT_FALSE(report.solve_failed) << k;
    ASSERT_TRUE(test::all_finite(*body)) << k;
    ASSERT_GE(test::lowest_free_node_height(*body) + 1e-3, kMargin - kTolerance) << "step " << k;
    EXPECT_EQ(report.projection.obstacle_unresolved, 0) << k;
    if (report.projection.obstacle_deepest_m > deepest_free) {
      deepest_free = report.projection.obstacle_deepest_m;
      deepest_step = k;
    }
  }
  // Not vacuous: the free motion did go into the floor, and the bar lies on it.
  EXPECT_GT(deepest_free, 1e-4) << "deepest at step " << deepest_step;
  EXPECT_LT(test::lowest_free_node_height(*body) + 1e-3, kMargin + 1e-4);
}

TEST(ObstacleProjection, FixedNodesNeverMove) {
  PressedBar bar;
  auto body = test::make_body(tongue_like(), bar.mesh, bar.fixed);
  ASSERT_TRUE(body);
  // The floor 2 mm above the bar's underside: the fixed face's lowest nodes
  // start inside it, and so do free ones, which the first step moves out.
  const Floor floor(2e-3);
  const ObstacleField* fields[] = {&floor};
  ContactStep step(*body, bar.links);
  step.set_obstacles(fields);
  for (int k = 0; k < 50; ++k) {
    const ContactSet set = bar.press(*body, 0.005, 0.5);
    const StepReport report = step.step(&set);
    if (k == 0) {
      EXPECT_GT(report.projection.obstacle_nodes, 0);
    }
    for (const std::uint32_t n : bar.fixed)
      ASSERT_EQ(body->position(n), body->rest_position(n)) << "node " << n;
    ASSERT_GE(test::lowest_free_node_height(*body) - 2e-3, kMargin - kTolerance) << "step " << k;
  }
}

TEST(ObstacleProjection, TheMovesAreCarriedAsVelocity) {
  // Gravity alone bends the soft bar onto a floor 1 mm below it; with the
  // correction carried into the next step the bar settles on the floor
  // instead of being pushed out and falling back every step.
  BodySettings settings = tongue_like();
  settings.gravity_m_per_s2 = Eigen::Vector3d(0, -9.81, 0);
  BarOverFloor run(settings);
  ASSERT_TRUE(run.body);
  auto& body = run.body;
  ContactStep& step = *run.step;
  int touching_steps = 0;
  for (int k = 0; k < 600; ++k) {
    const StepReport report = step.step(nullptr);
    touching_steps += report.projection.obstacle_nodes > 0 ? 1 : 0;
    ASSERT_GE(test::lowest_free_node_height(*body) + 1e-3, kMargin - kTolerance) << "step " << k;
  }
  EXPECT_GT(touching_steps, 0);  // it did reach the floor
  // At rest: the nodes no longer move from step to step. (Body velocities
  // are the free motion's; the correction enters in the next step's solve.)
  const std::vector<double> before(body->positions_m().begin(), body->positions_m().end());
  step.step(nullptr);
  double fastest = 0.0;
  for (std::size_t i = 0; i < before.size(); i += 3) {
    const auto x = body->positions_m();
    const Eigen::Vector3d moved(x[i] - before[i], x[i + 1] - before[i + 1],
                                x[i + 2] - before[i + 2]);
    fastest = std::max(fastest, moved.norm() / body->time_step_s());
  }
  EXPECT_LT(fastest, 1e-3);  // m/s, after 3 s
}

TEST(ObstacleProjection, NonFiniteNodesAndSamplesDoNotSpread) {
  const Floor floor(0.0);
  const Broken broken;
  std::vector<double> x = {0.0,
                           -1e-3,
                           0.0,  // inside the floor: moved out
                           std::numeric_limits<double>::quiet_NaN(),
                           0.0,
                           0.0,
                           0.0,
                           -2e-3,
                           0.0};  // fixed: stays
  const std::vector<double> inverse_mass = {1.0, 1.0, 0.0};
  const ObstacleField* good[] = {&floor};
  ObstacleProjection projection(good, 3);
  projection.begin_step();
  ProjectionReport report;
  EXPECT_EQ(projection.project(x, inverse_mass, report), 1);
  EXPECT_NEAR(x[1], kMargin, 1e-12);
  EXPECT_TRUE(std::isnan(x[3]));  // left as it was, not spread
  EXPECT_EQ(x[7], -2e-3);
  EXPECT_EQ(report.obstacle_non_finite, 1);
  EXPECT_EQ(report.obstacle_nodes, 1);
  EXPECT_NEAR(report.obstacle_deepest_m, 1e-3, 1e-12);

  const ObstacleField* bad[] = {&broken};
  ObstacleProjection refusing(bad, 3);
  std::vector<double> y = {0.0, -1e-3, 0.0, 0.0, 1e-3, 0.0, 0.0, 0.0, 0.0};
  const std::vector<double> before = y;
  const std::vector<double> all_free = {1.0, 1.0, 1.0};
  refusing.begin_step();
  ProjectionReport bad_report;
  EXPECT_EQ(refusing.project(y, all_free, bad_report), 0);
  EXPECT_EQ(y, before);
  EXPECT_EQ(bad_report.obstacle_non_finite, 3);
}

TEST(ObstacleProjection, ANodeDrivenPastAThinPlateIsPutBackOnItsOwnSide) {
  // A 1 mm plate; in one step a node goes from 1 mm above it to 0.3 mm past
  // its mid-plane (nearest to the far side), and another right through it.
  // Without the path, the first would be pushed out below and the second
  // left below: both tunnelled.
  const Plate plate(0.0, 0.5e-3);
  const ObstacleField* fields[] = {&plate};
  ObstacleProjection projection(fields, 2);
  const std::vector<double> start = {0.0, 1.5e-3, 0.0, 0.0, 1.5e-3, 0.0};
  std::vector<double> x = {0.0, -0.3e-3, 0.0, 0.0, -2e-3, 0.0};
  const std::vector<double> inverse_mass = {1.0, 1.0};
  projection.begin_step();
  ProjectionReport report;
  EXPECT_EQ(projection.project(x, inverse_mass, report, start), 2);
  EXPECT_NEAR(x[1], 0.5e-3 + kMargin, 1e-9);
  // Through and out the far side, outside the plate again: its path says
  // where it went in.
  EXPECT_NEAR(x[4], 0.5e-3 + kMargin, 1e-9);
}

TEST(ObstacleProjection, ANodeBeyondAPlateFromItsRestMayCrossBackHome) {
  // Both nodes rest 2 mm above the 1 mm plate. Node 0 is below it (it got
  // there somehow) and its step takes it back above: with the rest
  // positions it is let through, without them it is put back below, where
  // path-following would keep it for good. Node 1 is above, at home, and is
  // driven through to below: it is stopped at the plate whatever its rest.
  const Plate plate(0.0, 0.5e-3);
  const ObstacleField* fields[] = {&plate};
  const std::vector<double> rest = {0.0, 2e-3, 0.0, 1e-3, 2e-3, 0.0};
  const std::vector<double> start = {0.0, -1.5e-3, 0.0, 1e-3, 1.5e-3, 0.0};
  const std::vector<double> end = {0.0, 1.2e-3, 0.0, 1e-3, -1.5e-3, 0.0};
  const std::vector<double> inverse_mass = {1.0, 1.0};
  for (const bool with_rest : {true, false}) {
    ObstacleProjection projection(fields, 2);
    std::vector<double> x = end;
    projection.begin_step();
    ProjectionReport report;
    projection.project(x, inverse_mass, report, start,
                       with_rest ? std::span<const double>(rest) : std::span<const double>());
    if (with_rest) {
      EXPECT_EQ(x[1], end[1]);
      EXPECT_EQ(projection.nodes_returned(), 1);
    } else {
      EXPECT_NEAR(x[1], -0.5e-3 - kMargin, 1e-9);
      EXPECT_EQ(projection.nodes_returned(), 0);
    }
    EXPECT_NEAR(x[4], 0.5e-3 + kMargin, 1e-9) << with_rest;
  }
}

TEST(ObstacleProjection, ANodeBeyondAThickBoneIsLeftAloneUntilHome) {
  // A 6 mm bone. Node 0 rests 2 mm above it and is now below it: its step
  // takes it 3 mm back up, into the bone, and the bone leaves it alone (it
  // has to pass through to get home). Node 1, at home above it, is driven
  // 1 mm into the bone and is put back out, as before.
  const Plate bone(0.0, 3e-3);
  const ObstacleField* fields[] = {&bone};
  const std::vector<double> rest = {0.0, 5e-3, 0.0, 1e-3, 5e-3, 0.0};
  const std::vector<double> start = {0.0, -5e-3, 0.0, 1e-3, 4e-3, 0.0};
  std::vector<double> x = {0.0, -2e-3, 0.0, 1e-3, 2e-3, 0.0};
  const std::vector<double> inverse_mass = {1.0, 1.0};
  ObstacleProjection projection(fields, 2);
  projection.begin_step();
  ProjectionReport report;
  projection.project(x, inverse_mass, report, start, rest);
  EXPECT_EQ(x[1], -2e-3);
  EXPECT_EQ(projection.nodes_beyond(), 1);
  EXPECT_NEAR(x[4], 3e-3 + kMargin, 1e-9);
}

TEST(ObstacleProjection, APathStopsWhereItEntersTheMargin) {
  // A path from 1 mm above the floor to 1 mm below it, 3 mm along x: it
  // enters the margin at x = 1.2 mm and stops there.
  const Floor floor(0.0);
  const ObstacleField* fields[] = {&floor};
  const std::vector<double> start = {0.0, 1e-3, 0.0};
  const std::vector<double> inverse_mass = {1.0};
  ObstacleProjection projection(fields, 1);
  std::vector<double> x = {3e-3, -1e-3, 0.0};
  projection.begin_step();
  ProjectionReport report;
  projection.project(x, inverse_mass, report, start);
  EXPECT_NEAR(x[0], 1.2e-3, 1e-8);
  EXPECT_NEAR(x[1], kMargin, 1e-8);
}

TEST(ObstacleProjection, FarNodesAreNotSampledEveryStep) {
  // A floor 20 mm below a bar that stays put: once sampled, every node's
  // clearance proves it clear and the field is not asked again.
  PressedBar bar;
  BodySettings settings = tongue_like();
  settings.gravity_m_per_s2 = Eigen::Vector3d::Zero();
  auto body = test::make_body(settings, bar.mesh, bar.fixed);
  ASSERT_TRUE(body);
  const Floor floor(-0.02);
  const ObstacleField* fields[] = {&floor};
  ContactStep step(*body, bar.links);
  step.set_obstacles(fields);
  step.step(nullptr);
  const int first = floor.samples;
  EXPECT_EQ(static_cast<std::size_t>(first), body->node_count() - bar.fixed.size());
  for (int k = 0; k < 20; ++k) step.step(nullptr);
  EXPECT_EQ(floor.samples, first);
}

#ifndef FAHR_SANITIZE_BUILD
TEST(ObstacleProjection, StepAllocatesNothingOnceWarmed) {
  test::hook_suitesparse_allocations();
  BodySettings settings = tongue_like();
  settings.solver.refactor_period = 0;
  settings.solver.refactor_rotation_rad = 0.0;  // no refactorisation: CHOLMOD mallocs there
  BarOverFloor run(settings);
  ASSERT_TRUE(run.body);
  const PressedBar& bar = run.bar;
  auto& body = run.body;
  ContactStep& step = *run.step;
  ContactSet set = bar.press(*body, 0.015, 1.0);
  for (int k = 0; k < 5; ++k) {
    set.state_step = body->step_index();
    step.step(&set);
  }
  fahr::test::AllocationCounter counter;
  int moved = 0;
  for (int k = 0; k < 20; ++k) {
    set.state_step = body->step_index();
    moved += step.step(&set).projection.obstacle_nodes;
  }
  const long news = counter.count();
  const long suitesparse_allocs = counter.other_count();
  EXPECT_GT(moved, 0);  // the anatomy pass did work in the counted steps
  EXPECT_EQ(news, 0);
  EXPECT_EQ(suitesparse_allocs, 0);
}
#endif

}  // namespace
}  // namespace fahr::fem
