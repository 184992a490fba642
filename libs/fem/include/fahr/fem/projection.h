// Algorithm 1 of the paper (section 3.2): after the implicit step, sphere
// constraints are projected on positions by Gauss-Seidel, in the given order.
#pragma once

#include <cstdint>
#include <span>

#include "fahr/fem/contact_set.h"
#include "fahr/fem/sphere_links.h"

namespace fahr::fem {

// How a sphere's centre correction dc is shared by its nodes.
enum class SphereSpread : std::uint8_t {
  // Node i moves by (w_i / m_i) dc / sum_j (w_j^2 / m_j): the smallest
  // mass-weighted move (Algorithm 1 as written). With weights that do not
  // follow the nodal masses the lightest node takes nearly all of it.
  kMassWeighted,
  // Every free node of the sphere moves by the same dc / sum_free w_j: the
  // sphere's nodes translate together, so no tet among them is deformed,
  // let alone inverted, by its own sphere's correction, whatever its weights.
  kTranslation,
};

// Where a frozen contact holds its sphere.
enum class FrozenTarget : std::uint8_t {
  // The sphere's centre at the start of the step, on the FEM's own
  // positions: the paper's c' = c, "the old position of the sphere". Every
  // frozen sphere's target comes from one node configuration, so the holds
  // can all be met at once and the projection settles.
  kStepStart,
  // Contact::hold_centre_m, the haptic side's estimate of where the tool
  // keeps the sphere (contact_response.cpp capture_holds). It is made from
  // an older state and, without W, a fallback compliance, so on the pressed
  // neonatal tongue the holds sat millimetres from the FEM's centres and
  // from each other; pulled to such targets through shared nodes, alternated
  // with the anatomy, the projection moved a node past the divergence limit
  // in one step (fahr_overshoot_bench --response force-aware at ae54ed4,
  // the first frozen step).
  // Kept to compare.
  kHoldCentre,
};

struct ProjectionSettings {
  // Gauss-Seidel sweeps over all constraints at most (one sweep suffices for
  // contacts that share no nodes; coupled contacts need more).
  int max_sweeps = 20;
  // A sweep whose largest centre correction is below this ends the loop, m.
  // 1 um is far below what a trainee sees or feels on a 3 cm tongue.
  double tolerance_m = 1e-6;
  // Project the ContactSet's kObstacle entries. A body that keeps itself out
  // of the anatomy (ObstacleProjection) turns this off: those entries are
  // spheres against planes the haptic side found one FEM step earlier.
  bool project_obstacle_contacts = true;
  // kMassWeighted is the contract's; kTranslation made the neonatal
  // overshoot run diverge (docs/design/anatomy-contact.md) and is kept to compare.
  SphereSpread spread = SphereSpread::kMassWeighted;
  // kStepStart needs the step's start positions (project_contacts'
  // step_start_m); without them a frozen contact uses its hold centre.
  FrozenTarget frozen_target = FrozenTarget::kStepStart;
};

struct ProjectionReport {
  int sweeps = 0;
  int constraints = 0;           // active or frozen contacts projected
  int unmovable = 0;             // constraints whose nodes are all fixed
  int degenerate_normals = 0;    // active contacts with a zero normal, skipped
  int unknown_spheres = 0;       // sphere ids not in the links, skipped
  double last_correction_m = 0;  // largest |dc| of the last sweep, m
  bool converged = true;
  // The body's own anatomy projection (obstacle_projection.h); all 0 when
  // the body has no obstacles.
  int obstacle_rounds = 0;          // tool / anatomy alternations this step
  int obstacle_nodes = 0;           // distinct nodes moved out of the anatomy
  int obstacle_unresolved = 0;      // nodes left inside the margin by the last pass
  int obstacle_non_finite = 0;      // nodes with a non-finite position or sample, left alone
  double obstacle_deepest_m = 0.0;  // deepest node inside an obstacle before its move, m (>= 0)
  int obstacle_supported =
      0;               // nodes held by a support spring from the next step on (obstacle_support.h)
  int tool_nodes = 0;  // node moves out of the tool obstacle (ContactStep::set_tool_obstacle)
  // Nodes beyond a bone this step (obstacle_projection.h): let back through
  // it on their way home, and left alone by it.
  int obstacle_returned = 0;
  int obstacle_beyond = 0;
  // The volume floor (volume_floor.h), summed over the step's rounds: tets
  // found below it, and those its last pass left below.
  int volume_floor_below = 0;
  int volume_floor_unresolved = 0;
};

// Whether the contact is projected, and how. Obstacles are always hard: a
// frozen obstacle contact is treated as active.
bool contact_is_frozen(const Contact& contact);
bool contact_is_projected(const Contact& contact);
bool contact_is_projected(const Contact& contact, const ProjectionSettings& settings);

// Moves `positions_m` (3 per node) so that every active contact satisfies
// (c' - q) . n >= r (the sphere, radius included, stays on its side of the
// rigid surface, which is the plane) and every frozen contact c' = its
// target (ProjectionSettings::frozen_target; step_start_m: the positions at
// the start of the step, empty to use the hold centres).
// A correction dc moves node i by (w_i / m_i) dc / sum_j (w_j^2 / m_j):
// inverse_mass_per_node is 0 for fixed nodes, which therefore never move.
ProjectionReport project_contacts(const ContactSet& contacts, const SphereLinks& links,
                                  std::span<const double> inverse_mass_per_node,
                                  const ProjectionSettings& settings, std::span<double> positions_m,
                                  std::span<const double> step_start_m = {});

// The correction of one sphere, exposed for tests: returns false if all of
// its nodes are fixed (nothing can move).
bool move_sphere_centre(std::size_t sphere, const SphereLinks& links,
                        std::span<const double> inverse_mass_per_node, const Eigen::Vector3d& dc_m,
                        std::span<double> positions_m,
                        SphereSpread spread = SphereSpread::kMassWeighted);

}  // namespace fahr::fem
