// Which services a scene runs and which body pairs can touch.
#include "fahr/scene/plan.h"

#include <algorithm>
#include <stdexcept>

namespace fahr::scene {

namespace {

bool excluded(const Scene& scene, std::size_t a, std::size_t b) {
  const BodyIndexPair key{std::min(a, b), std::max(a, b)};
  const auto& list = scene.contact.exclude_pairs;
  return std::find(list.begin(), list.end(), key) != list.end();
}

bool declared(const Scene& scene, std::size_t a, std::size_t b) {
  const BodyIndexPair key{std::min(a, b), std::max(a, b)};
  const auto& list = scene.contact.include_pairs;
  return std::find(list.begin(), list.end(), key) != list.end();
}

// Why a deformable body and an obstacle are tested, or nullopt if they cannot
// touch: declared, or their boxes grown by the margin overlap, or a box is
// unknown (kept: a pair is only dropped when it provably cannot touch).
std::optional<PairReason> deformable_obstacle_reason(const Scene& scene,
                                                     std::span<const std::optional<Aabb>> bounds,
                                                     std::size_t deformable, std::size_t obstacle) {
  if (declared(scene, deformable, obstacle)) return PairReason::kDeclared;
  if (bounds.empty() || !bounds[deformable] || !bounds[obstacle]) {
    return PairReason::kBoundsUnknown;
  }
  const double margin = scene.contact.deformable_obstacle_margin_m;
  if (bounds[deformable]->inflated(margin).overlaps(*bounds[obstacle])) {
    return PairReason::kWithinMargin;
  }
  return std::nullopt;
}

std::optional<BodyPair> pair_of(const Scene& scene, std::span<const std::optional<Aabb>> bounds,
                                std::size_t i, std::size_t j) {
  const BodyRole ri = scene.bodies[i].role;
  const BodyRole rj = scene.bodies[j].role;
  if (excluded(scene, i, j) || ri == rj) return std::nullopt;  // same roles never touch
  if (ri == BodyRole::kTool || rj == BodyRole::kTool) {
    const std::size_t tool = ri == BodyRole::kTool ? i : j;
    const std::size_t other = tool == i ? j : i;
    const PairReason reason = scene.bodies[other].role == BodyRole::kDeformable
                                  ? PairReason::kToolDeformable
                                  : PairReason::kToolObstacle;
    return BodyPair{tool, other, PairKind::kTool, reason};
  }
  const std::size_t deformable = ri == BodyRole::kDeformable ? i : j;
  const std::size_t obstacle = deformable == i ? j : i;
  const auto reason = deformable_obstacle_reason(scene, bounds, deformable, obstacle);
  if (!reason) return std::nullopt;
  return BodyPair{deformable, obstacle, PairKind::kHard, *reason};
}

}  // namespace

ServicePlan derive_plan(const Scene& scene, std::span<const std::optional<Aabb>> world_bounds) {
  if (!world_bounds.empty() && world_bounds.size() != scene.bodies.size()) {
    throw std::invalid_argument("derive_plan: world_bounds has " +
                                std::to_string(world_bounds.size()) + " entries for " +
                                std::to_string(scene.bodies.size()) + " bodies");
  }
  ServicePlan plan;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    if (scene.bodies[i].role == BodyRole::kDeformable) plan.fem_bodies.push_back(i);
  }
  plan.tool_body = scene.tool_index();
  plan.run_fem = !plan.fem_bodies.empty();
  plan.run_haptic = plan.tool_body.has_value();
  plan.run_device_gateway = scene.device.has_value();
  plan.run_lockstep_clock = scene.run.mode == RunMode::kLockstep;
  for (std::size_t i = 0; i < scene.bodies.size(); ++i) {
    for (std::size_t j = i + 1; j < scene.bodies.size(); ++j) {
      if (const std::optional<BodyPair> pair = pair_of(scene, world_bounds, i, j)) {
        plan.pairs.push_back(*pair);
      }
    }
  }
  // Ordered by the indices as stored (tool or deformable first), so iteration
  // order is fixed for a scene: lockstep runs depend on it.
  std::sort(plan.pairs.begin(), plan.pairs.end(), [](const BodyPair& a, const BodyPair& b) {
    return std::tie(a.first, a.second) < std::tie(b.first, b.second);
  });
  return plan;
}

}  // namespace fahr::scene
