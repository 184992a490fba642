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
// The same holds for the free node of a held tet that the volume floor
// pushed off its fixed face (volume_floor.h): the fixed face is the
// attachment's bone, and the node is held along the floor's direction.
#pragma once

#include <Eigen/Core>
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

class ObstacleSupport {
 public:
  explicit ObstacleSupport(std::size_t node_count);

  // After a step's projections. start_m and free_m (3 per node, m): the
  // positions at the start of the step and after its implicit solve, before
  // any projection. `floor` (may be null): the step's volume floor, whose
  // moves of held tets' free nodes hold them too (where the anatomy moved a
  // node as well, the anatomy's normal is taken). Returns true if the held
  // set or a normal changed. No allocation.
  bool update(const ObstacleProjection& anatomy, const VolumeFloor* floor,
              std::span<const double> start_m, std::span<const double> free_m);
  // Lets every node go (a reset); returns true if any was held.
  bool clear();

  std::span<const NodeSupport> supports() const { return {supports_.data(), count_}; }

 private:
  std::vector<NodeSupport> supports_;  // capacity: every node
  std::vector<NodeSupport> previous_;
  std::size_t count_ = 0;
  std::vector<std::int32_t> slot_of_node_;  // index into previous_ while updating, -1 if not held
};

}  // namespace fahr::fem
