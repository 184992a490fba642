// Algorithm 1 of the paper (section 3.2): after the implicit step, sphere
// constraints are projected on positions by Gauss-Seidel, in the given order.
#pragma once

#include <Eigen/Core>
#include <span>

#include "fahr/fem/contact_set.h"
#include "fahr/fem/sphere_links.h"

namespace fahr::fem {

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
  int obstacle_supported = 0;       // nodes held by a support spring from the next step on
                                    // (obstacle_support.h)
  // Nodes beyond a bone this step (obstacle_projection.h): let back through
  // it on their way home, and left alone by it.
  int obstacle_returned = 0;
  int obstacle_beyond = 0;
  // The volume floor (volume_floor.h), summed over the step's rounds: tets
  // found below it, and those its last pass left below.
  int volume_floor_below = 0;
  int volume_floor_unresolved = 0;
  // The tool constraints' moves, each sphere's centre correction dc over
  // J M^-1 J^T (its impulse times h, kg m), summed over sweeps and rounds:
  // divided by h^2, the force the projection put on the tissue.
  Eigen::Vector3d tool_push_kg_m = Eigen::Vector3d::Zero();
};

// Whether the contact is projected, and how. Obstacles are always hard: a
// frozen obstacle contact is treated as active.
bool contact_is_frozen(const Contact& contact);
bool contact_is_projected(const Contact& contact);
bool contact_is_projected(const Contact& contact, const ProjectionSettings& settings);

// Moves `positions_m` (3 per node) so that every active contact satisfies
// (c' - q) . n >= r (the sphere, radius included, stays on its side of the
// rigid surface, which is the plane) and every frozen contact c' = c, its
// sphere's centre on step_start_m, the positions at the start of the step
// (the paper's "old position of the sphere": every target comes from one
// node configuration, so the holds can all be met at once).
// A correction dc moves node i by (w_i / m_i) dc / sum_j (w_j^2 / m_j):
// inverse_mass_per_node is 0 for fixed nodes, which therefore never move.
ProjectionReport project_contacts(const ContactSet& contacts, const SphereLinks& links,
                                  std::span<const double> inverse_mass_per_node,
                                  const ProjectionSettings& settings, std::span<double> positions_m,
                                  std::span<const double> step_start_m);

// The correction of one sphere, exposed for tests: returns false if all of
// its nodes are fixed (nothing can move). With `push_kg_m`, adds the move's
// mass-weighted size dc / (J M^-1 J^T) to it.
bool move_sphere_centre(std::size_t sphere, const SphereLinks& links,
                        std::span<const double> inverse_mass_per_node, const Eigen::Vector3d& dc_m,
                        std::span<double> positions_m, Eigen::Vector3d* push_kg_m = nullptr);

}  // namespace fahr::fem
