// The anatomy as the implicit solve sees it (ObstacleSupport inside
// fem::ContactStep): a soft bar pressed onto a rigid floor is held there by
// support springs, so the compliance W the haptic solve reads for a point on
// its top feels the floor (the bar compresses instead of bending through
// it); the springs do not glue: pulled up, the bar is let go and lifts off.
#include "fahr/fem/obstacle_support.h"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "fahr/fem/contact_step.h"
#include "fahr/fem/obstacle_projection.h"
#include "scenes.h"

namespace fahr::fem {
namespace {

// The rigid floor y < level (outward normal +y), exact.
class Floor final : public ObstacleField {
 public:
  explicit Floor(double level_m) : level_m_(level_m) {}
  ObstacleSample sample(const Eigen::Vector3d& p) const noexcept override {
    return {p.y() - level_m_, Eigen::Vector3d::UnitY()};
  }

 private:
  double level_m_;
};

BodySettings tongue_like() {
  BodySettings s;  // neonatal tongue material (E 10 kPa, nu 0.45)
  s.sleep.enabled = false;
  s.time_step = std::chrono::duration<double>(1.0 / 200.0);
  return s;
}

// The 30 x 10 x 10 mm bar, its x = 0 face fixed, 1 mm above a floor; one
// zero-radius sphere on the top node nearest the free end's middle, whose
// W_yy is read.
struct BarOnFloor {
  BodyMesh mesh = test::bar_mesh(2);
  std::vector<std::uint32_t> fixed = test::fixed_x0(mesh);
  std::vector<std::uint32_t> free_half_top;
  std::uint32_t probe = 0;
  SphereLinks links;
  std::unique_ptr<Body> body;
  Floor floor{-1e-3};
  std::unique_ptr<ContactStep> step;
  std::vector<double> push;  // extra force, 3 per node, N

  explicit BarOnFloor(double support_ratio) {
    free_half_top = test::nodes_where(
        mesh, [](const Eigen::Vector3d& p) { return p.x() > 0.0149 && p.y() > 0.0099; });
    double best = std::numeric_limits<double>::infinity();
    for (const std::uint32_t n : free_half_top) {
      const double d = (mesh.nodes_m[n] - Eigen::Vector3d(0.03, 0.01, 0.005)).norm();
      if (d < best) {
        best = d;
        probe = n;
      }
    }
    const double w = 1.0;
    EXPECT_EQ(links.add_sphere({&probe, 1}, {&w, 1}, 0.0), "");
    body = test::make_body(tongue_like(), mesh, fixed);
    step = std::make_unique<ContactStep>(*body, links);
    ObstacleProjectionSettings settings;
    settings.support_stiffness_ratio = support_ratio;
    const ObstacleField* fields[] = {&floor};
    step->set_obstacles(fields, settings);
    const std::uint32_t sphere = 0;
    EXPECT_TRUE(step->fix_compliance_spheres({&sphere, 1}));
    push.assign(3 * body->node_count(), 0.0);
  }
  // A total vertical force on the free half's top nodes, N (< 0 down).
  void set_push(double total_n) {
    std::fill(push.begin(), push.end(), 0.0);
    for (const std::uint32_t n : free_half_top)
      push[3 * n + 1] = total_n / static_cast<double>(free_half_top.size());
  }
  double w_yy() const { return static_cast<double>(step->compliance()[4]); }
};

TEST(ObstacleSupport, ABodyPressedOntoTheFloorFeelsItInItsCompliance) {
  BarOnFloor with(100.0), without(0.0);
  ASSERT_TRUE(with.body && without.body);
  const double free_w = with.w_yy();
  with.set_push(-0.5);
  without.set_push(-0.5);
  for (int k = 0; k < 200; ++k) {  // 1 s: both bend onto the floor
    const StepReport a = with.step->step(nullptr, with.push);
    const StepReport b = without.step->step(nullptr, without.push);
    ASSERT_FALSE(a.solve_failed || b.solve_failed) << k;
    ASSERT_TRUE(test::all_finite(*with.body)) << k;
  }
  // Both lie on the floor (the projection alone keeps them out of it).
  EXPECT_LT(test::lowest_free_node_height(*with.body) + 1e-3, 0.2e-3 + 1e-5);
  EXPECT_LT(test::lowest_free_node_height(*without.body) + 1e-3, 0.2e-3 + 1e-5);
  EXPECT_GT(with.body->support_count(), 0u);
  EXPECT_EQ(without.body->support_count(), 0u);
  // Without support W still believes the bar bends freely, as at rest
  // (0.033 against 0.036 m/N here); with it, pressing the top compresses
  // the 10 mm of soft material under the point instead (0.010 m/N).
  EXPECT_GT(without.w_yy(), 0.8 * free_w);
  EXPECT_LT(with.w_yy(), 0.4 * without.w_yy()) << "free " << free_w;
}

TEST(ObstacleSupport, TheSpringsLetGoOfABodyPulledOffTheFloor) {
  BarOnFloor bar(100.0);
  ASSERT_TRUE(bar.body);
  bar.set_push(-0.5);
  for (int k = 0; k < 200; ++k) bar.step->step(nullptr, bar.push);
  ASSERT_GT(bar.body->support_count(), 0u);
  const double resting = test::lowest_free_node_height(*bar.body);
  bar.set_push(+0.5);
  int released_at = -1;
  for (int k = 0; k < 200; ++k) {
    const StepReport report = bar.step->step(nullptr, bar.push);
    if (released_at < 0 && report.projection.obstacle_supported == 0) released_at = k;
  }
  // Every node is let go within the first steps of the pull (not glued
  // until the pull could tear it off), and the bar leaves the floor.
  EXPECT_GE(released_at, 0);
  EXPECT_LE(released_at, 3);
  EXPECT_GT(test::lowest_free_node_height(*bar.body), resting + 1e-3);
}

}  // namespace
}  // namespace fahr::fem
