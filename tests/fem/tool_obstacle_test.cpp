// The tool as an obstacle of the whole body (ContactStep::set_tool_obstacle):
// a rigid slab lowered into a soft bar pushes every node it reaches out,
// not only the spheres a ContactSet names, and gives the solve no support
// spring (W must not feel the tool).
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "fahr/fem/contact_step.h"
#include "scenes.h"

namespace fahr::fem {
namespace {

// The rigid slab y > level_m (outward normal -y), exact; the test moves it.
class Slab final : public ObstacleField {
 public:
  double level_m = 0.0;
  ObstacleSample sample(const Eigen::Vector3d& p) const noexcept override {
    return {level_m - p.y(), -Eigen::Vector3d::UnitY()};
  }
};

BodySettings soft() {
  BodySettings s;  // neonatal tongue material (E 10 kPa, nu 0.45)
  s.sleep.enabled = false;
  s.time_step = std::chrono::duration<double>(1.0 / 200.0);
  s.gravity_m_per_s2.setZero();  // the bar stays where it is unless pushed
  return s;
}

// Highest node of the bar's free half (x > 15 mm), m.
double highest_free_node(const Body& body, const BodyMesh& mesh) {
  double top = -1.0;
  for (std::uint32_t n = 0; n < body.node_count(); ++n) {
    if (mesh.nodes_m[n].x() > 0.015) top = std::max(top, body.position(n).y());
  }
  return top;
}

// The 30 x 10 x 10 mm bar, its x = 0 face fixed, under a slab lowered from
// its top (10 mm) by 0.5 mm a step to 7 mm, no ContactSet at all.
double lowest_reach_of_slab(bool tool_obstacle, int& supported) {
  const BodyMesh mesh = test::bar_mesh(2);
  const auto fixed = test::fixed_x0(mesh);
  SphereLinks links;
  auto body = test::make_body(soft(), mesh, fixed);
  ContactStep step(*body, links);
  Slab slab;
  slab.level_m = 0.010;
  if (tool_obstacle) step.set_tool_obstacle(&slab);
  double worst = 0.0;  // highest free node above the slab's face, m
  for (int k = 0; k < 20; ++k) {
    slab.level_m = std::max(0.007, slab.level_m - 0.5e-3);
    step.step(nullptr);
    worst = std::max(worst, highest_free_node(*body, mesh) - slab.level_m);
  }
  supported = static_cast<int>(body->support_count());
  return worst;
}

TEST(ToolObstacle, KeepsEveryNodeOutOfTheToolWithoutAContactSet) {
  int supported = -1;
  // Without it the bar stays where it was, 3 mm into the slab: what the
  // tongue does around a still blade to every sphere the ContactSet omits.
  EXPECT_GT(lowest_reach_of_slab(false, supported), 2.9e-3);
  EXPECT_LT(lowest_reach_of_slab(true, supported), 1e-6);
  EXPECT_EQ(supported, 0);  // no spring: the compliance does not feel the tool
}

}  // namespace
}  // namespace fahr::fem
