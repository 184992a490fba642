// The run plan: which services run, and which body pairs are ever tested.
#include "fahr/scene/plan.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>

#include "test_support.h"

namespace fahr::scene::test {
namespace {

Aabb box(double x0, double x1) {
  return Aabb{Eigen::Vector3d(x0, 0.0, 0.0), Eigen::Vector3d(x1, 0.01, 0.01)};
}

bool has_pair(const ServicePlan& plan, std::size_t a, std::size_t b) {
  return std::any_of(plan.pairs.begin(), plan.pairs.end(), [&](const BodyPair& p) {
    return (p.first == a && p.second == b) || (p.first == b && p.second == a);
  });
}

// Bodies of kMinimalScene: 0 tongue (deformable), 1 blade (tool),
// 2 palate and 3 jaw (obstacles).
TEST(ScenePlan, EveryRoleRunsEveryService) {
  const ServicePlan plan = derive_plan(*parse(kMinimalScene));
  EXPECT_TRUE(plan.run_fem);
  EXPECT_TRUE(plan.run_haptic);
  EXPECT_TRUE(plan.run_device_gateway);
  EXPECT_EQ(plan.fem_bodies, (std::vector<std::size_t>{0}));
  EXPECT_EQ(plan.tool_body, 1u);
}

TEST(ScenePlan, NoDeviceMeansNoGateway) {
  const auto scene = parse(replaced("device:\n  backend: simulated\n", ""));
  const ServicePlan plan = derive_plan(*scene);
  EXPECT_FALSE(plan.run_device_gateway);
  EXPECT_TRUE(plan.run_haptic);  // the tool is still there
}

TEST(ScenePlan, NoToolMeansNoHaptic) {
  std::string text = replaced("device:\n  backend: simulated\n", "");
  text.replace(text.find("role: tool"), 10, "role: obstacle");
  const ServicePlan plan = derive_plan(*parse(text));
  EXPECT_FALSE(plan.run_haptic);
  EXPECT_FALSE(plan.run_device_gateway);
  EXPECT_TRUE(plan.run_fem);
  EXPECT_FALSE(plan.tool_body.has_value());
}

TEST(ScenePlan, LockstepRunsTheClock) {
  const auto scene = parse(std::string(kMinimalScene) + "run:\n  mode: lockstep\n");
  EXPECT_TRUE(derive_plan(*scene).run_lockstep_clock);
}

TEST(ScenePlan, WithoutBoundsEveryPossiblePairIsKept) {
  const ServicePlan plan = derive_plan(*parse(kMinimalScene));
  ASSERT_EQ(plan.pairs.size(), 5u);
  EXPECT_TRUE(has_pair(plan, 1, 0));
  EXPECT_TRUE(has_pair(plan, 1, 2));
  EXPECT_TRUE(has_pair(plan, 1, 3));
  EXPECT_TRUE(has_pair(plan, 0, 2));
  EXPECT_TRUE(has_pair(plan, 0, 3));
  EXPECT_FALSE(has_pair(plan, 2, 3));  // obstacle/obstacle never
  for (const BodyPair& pair : plan.pairs) {
    if (pair.kind == PairKind::kHard) {
      EXPECT_EQ(pair.reason, PairReason::kBoundsUnknown);
    }
  }
}

TEST(ScenePlan, PairsAreFilteredByMarginDeclarationAndExclusion) {
  // Tongue [0, 0.04]; palate 3 mm beyond its end (within the 5 mm margin);
  // jaw 10 cm away; the blade far away too (tool pairs ignore distance).
  const std::vector<std::optional<Aabb>> bounds = {box(0.0, 0.04), box(0.5, 0.6), box(0.043, 0.06),
                                                   box(0.14, 0.2)};
  const auto scene = parse(kMinimalScene);
  ServicePlan plan = derive_plan(*scene, bounds);
  EXPECT_TRUE(has_pair(plan, 0, 2));
  EXPECT_FALSE(has_pair(plan, 0, 3));  // too far to touch: never tested
  EXPECT_TRUE(has_pair(plan, 1, 0));
  EXPECT_TRUE(has_pair(plan, 1, 3));
  EXPECT_FALSE(has_pair(plan, 2, 3));
  const auto palate = std::find_if(plan.pairs.begin(), plan.pairs.end(),
                                   [](const BodyPair& p) { return p.second == 2 && p.first == 0; });
  ASSERT_NE(palate, plan.pairs.end());
  EXPECT_EQ(palate->kind, PairKind::kHard);
  EXPECT_EQ(palate->reason, PairReason::kWithinMargin);

  // Declared in contact: the far jaw is tested after all.
  const auto declared =
      parse(std::string(kMinimalScene) + "contact:\n  include_pairs: [[jaw, tongue]]\n");
  plan = derive_plan(*declared, bounds);
  EXPECT_TRUE(has_pair(plan, 0, 3));

  // A smaller margin drops the palate.
  const auto tight =
      parse(std::string(kMinimalScene) + "contact:\n  deformable_obstacle_margin_m: 0.001\n");
  EXPECT_FALSE(has_pair(derive_plan(*tight, bounds), 0, 2));

  // Excluded pairs are never tested, tool pairs included.
  const auto excluded = parse(std::string(kMinimalScene) +
                              "contact:\n  exclude_pairs: [[blade, palate], [palate, tongue]]\n");
  plan = derive_plan(*excluded, bounds);
  EXPECT_FALSE(has_pair(plan, 1, 2));
  EXPECT_FALSE(has_pair(plan, 0, 2));
  EXPECT_TRUE(has_pair(plan, 1, 3));
}

TEST(ScenePlan, PairsAreOrderedAndToolOrDeformableComesFirst) {
  const ServicePlan plan = derive_plan(*parse(kMinimalScene));
  for (std::size_t i = 0; i < plan.pairs.size(); ++i) {
    const BodyPair& pair = plan.pairs[i];
    const std::size_t expected_first = pair.kind == PairKind::kTool ? 1u : 0u;
    EXPECT_EQ(pair.first, expected_first);
    if (i > 0) {
      const BodyPair& prev = plan.pairs[i - 1];
      EXPECT_LT(std::tie(prev.first, prev.second), std::tie(pair.first, pair.second));
    }
  }
}

TEST(ScenePlan, BoundsOfTheWrongLengthAreRejected) {
  const std::vector<std::optional<Aabb>> bounds(2);
  EXPECT_THROW(derive_plan(*parse(kMinimalScene), bounds), std::invalid_argument);
}

}  // namespace
}  // namespace fahr::scene::test
