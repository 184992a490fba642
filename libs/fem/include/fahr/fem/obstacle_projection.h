// The FEM's own non-penetration of the static rigid anatomy: after the
// implicit step, every free node closer to an obstacle than a margin is
// moved out along the obstacle's normal to the margin, on the positions of
// this very step. The haptic side's sphere contacts against the anatomy are
// one FEM step late and see spheres, not the surface; pressed by the blade,
// the tongue tunnelled through the jaw between two such steps
// (docs/design/anatomy-contact.md). Nodes are enough: the tongue's
// surface is its boundary nodes, and a face between two nodes that stay out
// of the bone can only dip into it where the bone is sharper than an element.
//
// A node that was clear of an obstacle at the start of the step is put back
// where its path first came within the margin (the path is sphere-traced
// from its start), not at the surface nearest to where it ended: pushed
// deeper than half a bone's thickness in one step, or right through a thin
// bone, the nearest surface is the far side, and the node would tunnel
// through (the neonatal tongue under the blade reached 7.7 mm into the jaw
// in one 5 ms step).
//
// A node can still end up beyond a thin bone (pushed through by conflicting
// constraints, or along the normal from deep inside). Path-following would
// then keep it there for good: on the neonatal overshoot a node far from
// rest, its rest on the other side of the jaw, was pulled back through the
// bone by its elements each step and put back each step, its inverted tets
// pinned for the rest of the run. So with the rest positions given, a
// path that crosses a surface is let through when it brings a node home:
// the segment from the node's rest position to its start enters the
// obstacle and the segment from its rest position to where the path ends
// does not.
//
// The nodes a pass moved are what obstacle_support.h holds with springs in
// the next step's system matrix, so the implicit solve and W feel the bone.
//
// Fixed nodes (inverse mass 0) never move. Capacities are fixed at
// construction; a pass allocates nothing. Each node keeps a lower bound of
// its distance to every obstacle (the sampled distance minus how far it has
// moved since: a signed distance is 1-Lipschitz), so a node far from bone is
// not sampled again until it has travelled that far.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fahr/fem/obstacle_field.h"
#include "fahr/fem/projection.h"

namespace fahr::fem {

struct ObstacleProjectionSettings {
  // Nodes closer than this to an obstacle are moved out to it, m, [0, 0.01].
  // 0.2 mm: thin enough not to show (a tenth of a tongue element), thick
  // enough that a node resting on the bone is not inside it after the
  // rounding of the distance field's closest-point normal.
  double margin_m = 0.2e-3;
  // A node left this little inside the margin counts as out, m (> 0).
  double tolerance_m = 1e-6;
  // Moves of one node against one obstacle per pass, >= 1: on a curved
  // surface a move along the normal lands a little off the margin, so the
  // node is sampled again after each move.
  int max_moves_per_node = 3;
  // Tool projection / anatomy projection alternations per step, >= 1
  // (ContactStep): the anatomy's pass comes last, so bone wins over a tool
  // constraint that would press a node into it. A step ends as soon as a
  // round leaves nothing to redo, so the cap only costs where the tool, the
  // volume floor and the bone disagree: 4 ran out in 500 of the 3,200 FEM
  // steps of the 100 kPa overshoot and left 3 thin tets by the bone
  // inverted; 32 leaves none there and none in the 20 s intubation, for a
  // FEM step p99 of 54 ms against 37 (docs/design/anatomy-contact.md,
  // the anatomy's rounds).
  int max_rounds = 32;
  // Nodes the anatomy moved are held by a spring along the bone's normal in
  // the next steps' system matrix (obstacle_support.h), this many times
  // stiffer than the node's own diagonal of A, >= 0; 0: no springs, the
  // anatomy acts only through this projection. 100: pressing a supported
  // node into the bone moves it a hundredth as far as pressing it free.
  double support_stiffness_ratio = 100.0;
  // With rest positions: a node whose straight segment from its rest
  // position to its start passes deeper than this into an obstacle is taken
  // to be beyond it (it went through), and that obstacle leaves it alone
  // until it is home, m (> 0). A node sliding over a bone's ridge has a
  // chord only the ridge's sagitta deep (3 mm over a 5 mm radius: 0.23 mm).
  double beyond_depth_m = 1e-3;
};

class ObstacleProjection {
 public:
  // `fields` (each must outlive this object) are static, in the body's
  // frame; node_count is the body's.
  ObstacleProjection(std::span<const ObstacleField* const> fields, std::size_t node_count,
                     const ObstacleProjectionSettings& settings = {});

  // Forgets which nodes moved this step; call before the step's first pass.
  void begin_step();
  // Forgets every clearance (every node is sampled in the next pass): after
  // positions were set from outside (a reset to rest, a teleport).
  void forget_clearances();

  // One pass: moves every free node closer than the margin out of every
  // obstacle, in place (3 per node, m). start_positions_m (3 per node, m, or
  // empty): where the nodes were at the start of the step, for the entry
  // point of a node that crossed a surface. rest_positions_m (3 per node, m,
  // or empty): lets a node beyond a bone cross back home (see above). Adds to
  // report's obstacle fields and returns how many nodes this pass moved.
  int project(std::span<double> positions_m, std::span<const double> inverse_mass_per_node,
              ProjectionReport& report, std::span<const double> start_positions_m = {},
              std::span<const double> rest_positions_m = {});
  // Nodes let back through a surface, and nodes beyond an obstacle left
  // alone by it, since begin_step().
  int nodes_returned() const { return nodes_returned_; }
  int nodes_beyond() const { return nodes_beyond_; }

  // Whether `node` was moved since begin_step(), and the outward unit normal
  // of the obstacle that moved it last (where it put the node).
  bool moved(std::size_t node) const { return moved_[node] != 0; }
  const Eigen::Vector3d& move_normal(std::size_t node) const { return move_normal_[node]; }
  std::size_t node_count() const { return moved_.size(); }
  const ObstacleProjectionSettings& settings() const { return settings_; }

 private:
  enum class NodeOutcome { kClear, kMoved, kUnresolved, kNonFinite };
  NodeOutcome project_node(std::size_t node, const Eigen::Vector3d* start,
                           const Eigen::Vector3d* rest, Eigen::Vector3d& x,
                           ProjectionReport& report);
  // Whether the segment a -> b comes within `level` of the field (sphere
  // traced); `if_undecided` when the trace runs out of samples or the field
  // cannot answer.
  bool segment_enters(const ObstacleField& field, const Eigen::Vector3d& a,
                      const Eigen::Vector3d& b, double level_m, bool if_undecided) const;
  // Follows the path start -> x; if it meets the margin, moves x (and its
  // sample s) there and returns how far, else returns 0.
  double enter_along_path(const ObstacleField& field, const Eigen::Vector3d& start,
                          Eigen::Vector3d& x, ObstacleSample& s, ProjectionReport& report) const;
  // The point of the segment start -> x where the field's distance is
  // `level` (start at or above it, x below it), by regula falsi.
  Eigen::Vector3d entry_point(const ObstacleField& field, const Eigen::Vector3d& start,
                              double start_distance_m, const Eigen::Vector3d& x, double distance_m,
                              double level_m) const;
  // Lowers every clearance of `node` by `distance_m` (it moved that far).
  void spend_clearance(std::size_t node, double distance_m);

  std::vector<const ObstacleField*> fields_;
  ObstacleProjectionSettings settings_;
  // Per node and field (node-major): a lower bound of the distance from
  // sampled_at_m_[node] to the field, m; -inf until sampled.
  std::vector<double> clearance_m_;
  std::vector<Eigen::Vector3d> sampled_at_m_;  // per node, m
  std::vector<std::uint8_t> moved_;            // per node: moved since begin_step()
  std::vector<Eigen::Vector3d> move_normal_;   // per node: normal of its last move
  int nodes_moved_ = 0;
  int nodes_returned_ = 0;
  int nodes_beyond_ = 0;
  // Per node and field: whether the node is beyond the obstacle this step
  // (0 not checked yet, 1 no, 2 yes); cleared by begin_step().
  std::vector<std::uint8_t> beyond_;
};

}  // namespace fahr::fem
