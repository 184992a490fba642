// The static anatomy as seen by the implicit solve: nodes the bone holds get
// a stiff spring along the bone's normal in the next step's system matrix A.
//
// Why: ObstacleProjection keeps nodes out of bone after each step, but A,
// and so the compliance W = h^2 J A^-1 J^T the haptic solve uses, do not
// know the bone is there. Pressed by the blade, a tongue that rests on the
// jaw is as compliant in W as a tongue floating free: the haptic solve lets
// the tool in as if the tongue could move away, the FEM's step moves it into
// the jaw, the anatomy pass puts it back under the blade, and the tissue
// between is flattened until the tets invert and the blade passes through
// (bench/overshoot, docs/design/anatomy-contact.md). A spring
// k n n^T on a held node's diagonal block makes A, the free motion and W
// feel the support: pushing a tongue onto the jaw compresses it.
//
// The spring's rest length is the node's position at the start of the step,
// so it adds no force, only stiffness against further motion along n (none
// along the surface: the bone is frictionless). It is one-sided by its
// active set: a node the anatomy pass moved this step is held from the next
// step on; a held node whose free motion heads away from the bone is let go
// (its spring would have pulled), so tissue lifts off after one step.
//
// The volume floor (volume_floor.h) is held the same way: a tet the floor
// opened in a step gets, from the next step on, a spring along the
// direction it was opened in (its volume's gradient over its free nodes)
// in A, k d d^T over its four nodes' blocks; it is let go when its free
// motion opens it, or as soon as the floor is out of force (the step
// passes no floor: nothing presses the body). For a held tet (three nodes
// fixed) that is a node support of its fourth node along the fixed face's
// normal.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace fahr::fem {

class ObstacleProjection;
class VolumeFloor;

// One held node: its index and the bone's outward unit normal there.
struct NodeSupport {
  std::uint32_t node = 0;
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

// One tet the volume floor holds: its index and the unit direction (per
// node, zero on fixed nodes; the 12 entries of length 1) it is held along.
struct TetSupport {
  std::uint32_t tet = 0;
  std::array<Eigen::Vector3d, 4> direction{};
};

class ObstacleSupport {
 public:
  // tet_count: the body's tets (0: no volume floor).
  ObstacleSupport(std::size_t node_count, std::size_t tet_count);

  // After a step's projections. start_m and free_m (3 per node, m): the
  // positions at the start of the step and after its implicit solve, before
  // any projection. `anatomy` and `floor` (either may be null): the step's
  // anatomy pass, whose moved nodes are held, and its volume floor, whose
  // moved tets are held; a null floor lets every held tet go. Returns true
  // if a held set or a direction changed.
  // No allocation.
  bool update(const ObstacleProjection* anatomy, const VolumeFloor* floor,
              std::span<const double> start_m, std::span<const double> free_m);
  // Lets every node and tet go (a reset); returns true if any was held.
  bool clear();

  std::span<const NodeSupport> supports() const { return {supports_.data(), count_}; }
  std::span<const TetSupport> tet_supports() const { return {tets_.data(), tet_count_}; }

 private:
  bool update_tets(const VolumeFloor* floor, std::span<const double> start_m,
                   std::span<const double> free_m);

  std::vector<NodeSupport> supports_;  // capacity: every node
  std::vector<NodeSupport> previous_;
  std::size_t count_ = 0;
  std::vector<std::int32_t> slot_of_node_;  // index into previous_ while updating, -1 if not held
  std::vector<TetSupport> tets_;            // capacity: every tet
  std::vector<TetSupport> previous_tets_;
  std::size_t tet_count_ = 0;
  std::vector<std::int32_t> slot_of_tet_;
};

}  // namespace fahr::fem
