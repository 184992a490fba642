// What a scene runs and tests: the services it needs and the body pairs that
// can touch. Collision code iterates over ServicePlan::pairs and nothing else.
#pragma once

#include <cstddef>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "fahr/scene/aabb.h"
#include "fahr/scene/scene.h"

namespace fahr::scene {

enum class PairKind {
  kTool,  // tool against a body: force-aware (or penalty) response
  kHard,  // deformable against rigid anatomy: always a hard constraint
};

// Why a pair is tested.
enum class PairReason {
  kToolDeformable,
  kToolObstacle,
  kDeclared,       // contact.include_pairs
  kWithinMargin,   // world boxes within contact.deformable_obstacle_margin_m
  kBoundsUnknown,  // no bounds given: kept, since it cannot be ruled out
};

std::string_view to_string(PairKind kind);
std::string_view to_string(PairReason reason);

struct BodyPair {
  // Indices into Scene::bodies. For kTool pairs first is the tool; for kHard
  // pairs first is the deformable body.
  std::size_t first = 0;
  std::size_t second = 0;
  PairKind kind = PairKind::kHard;
  PairReason reason = PairReason::kBoundsUnknown;
};

struct ServicePlan {
  bool run_device_gateway = false;      // the scene has a device
  bool run_haptic = false;              // the scene has a tool
  bool run_fem = false;                 // the scene has a deformable body
  bool run_lockstep_clock = false;      // mode is lockstep
  std::vector<std::size_t> fem_bodies;  // deformable body indices, file order
  std::optional<std::size_t> tool_body;
  // Sorted by (first, second); no pair twice; obstacle/obstacle, deformable/
  // deformable and excluded pairs never appear.
  std::vector<BodyPair> pairs;
};

// world_bounds: empty, or one entry per body (world frame, m, after scale and
// pose), as the caller computed from the loaded meshes. A deformable/obstacle
// pair with an unknown bound is kept. Throws std::invalid_argument when
// world_bounds is neither empty nor bodies.size() long.
ServicePlan derive_plan(const Scene& scene, std::span<const std::optional<Aabb>> world_bounds = {});

}  // namespace fahr::scene
