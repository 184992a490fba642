// Contact response and tool coupling, and which body pairs the
// scene includes or excludes from contact testing by declaration.
#pragma once

#include <cstddef>
#include <string_view>
#include <utility>
#include <vector>

#include "fahr/scene/defaults.h"

namespace fahr::scene {

enum class ContactResponse {
  kForceAware,  // the paper's constraint: freeze past the renderable force
  kPenalty,     // baseline: force proportional to penetration
};

// What the force-aware tool does while the device has lost track.
enum class HeldProxy {
  kLoad,  // stays; the tissue is held by the limited load, force only (default)
  kStay,  // stays; the spheres are held where the FEM's step found them (the paper's c' = c)
};

std::string_view to_string(ContactResponse response);
std::string_view to_string(HeldProxy held);

// Two indices into Scene::bodies, first < second.
using BodyIndexPair = std::pair<std::size_t, std::size_t>;

struct ContactSettings {
  ContactResponse response = ContactResponse::kForceAware;
  double coupling_stiffness_npm = kDefaultCouplingStiffnessNPerM;  // N/m, (0, 1e5]
  double coupling_damping_nspm = kDefaultCouplingDampingNsPerM;    // N s/m, [0, 1e3]
  // Fraction of the renderable force below which frozen tool constraints
  // re-activate: they do at (1 - hysteresis) * limit, [0, 0.9].
  double force_aware_hysteresis = kDefaultForceAwareHysteresis;
  HeldProxy held_proxy = HeldProxy::kLoad;
  double penalty_stiffness_npm = kDefaultPenaltyStiffnessNPerM;  // N/m, (0, 1e6]
  // Deformable/obstacle pairs whose world boxes come within this are tested, m, [0, 1].
  double deformable_obstacle_margin_m = kDefaultDeformableObstacleMarginM;
  // Deformable/obstacle pairs declared in contact whatever their distance.
  std::vector<BodyIndexPair> include_pairs;
  // Pairs never tested, whatever their roles.
  std::vector<BodyIndexPair> exclude_pairs;
  // The tool against rigid anatomy: the proxy stops at bone (hard rows).
  // false: the tool passes through rigid bodies (only the deformable body
  // resists it), e.g. while the FEM cannot take a blade wedged against bone.
  bool tool_stops_at_anatomy = true;
};

}  // namespace fahr::scene
