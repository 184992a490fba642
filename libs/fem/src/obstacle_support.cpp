// Which nodes the anatomy holds (see obstacle_support.h).
#include "fahr/fem/obstacle_support.h"

#include <algorithm>

#include "fahr/fem/obstacle_projection.h"
#include "fahr/fem/volume_floor.h"

namespace fahr::fem {
namespace {

// A held node whose free motion leaves the bone by more than this in one
// step is let go, m: 0.1 um, far below anything visible, far above the
// rounding of positions of a few centimetres.
constexpr double kLiftOffM = 1e-7;
// A held node keeps the normal it was held along while the bone's normal
// under it stays within this angle (cos of 0.1 rad, the angle at which a
// lagged factorisation is refreshed for an element's rotation): the spring's
// direction is then off by less than the factor's own lag, and the field's
// gradient, which differs in the last bits whenever the node moves, does not
// change A in every step.
constexpr double kSameNormalCos = 0.995004165278025766;

}  // namespace

ObstacleSupport::ObstacleSupport(std::size_t node_count)
    : supports_(node_count), previous_(node_count), slot_of_node_(node_count, -1) {}

bool ObstacleSupport::clear() {
  const bool had = count_ > 0;
  count_ = 0;
  return had;
}

bool ObstacleSupport::update(const ObstacleProjection& anatomy, const VolumeFloor* floor,
                             std::span<const double> start_m, std::span<const double> free_m) {
  const std::size_t previous_count = count_;
  std::copy_n(supports_.begin(), previous_count, previous_.begin());
  for (std::size_t i = 0; i < previous_count; ++i)
    slot_of_node_[previous_[i].node] = static_cast<std::int32_t>(i);
  const std::size_t nodes =
      std::min({anatomy.node_count(), supports_.size(), start_m.size() / 3, free_m.size() / 3});
  bool changed = false;
  count_ = 0;
  // Node order, so the set (and A) does not depend on the order of moves.
  for (std::size_t n = 0; n < nodes; ++n) {
    const std::int32_t slot = slot_of_node_[n];
    const bool on_bone = anatomy.moved(n);
    if (on_bone || (floor != nullptr && floor->held_moved(n))) {
      const Eigen::Vector3d& normal = on_bone ? anatomy.move_normal(n) : floor->held_normal(n);
      if (slot >= 0 &&
          previous_[static_cast<std::size_t>(slot)].normal.dot(normal) >= kSameNormalCos) {
        supports_[count_++] = previous_[static_cast<std::size_t>(slot)];
        continue;
      }
      supports_[count_++] = NodeSupport{static_cast<std::uint32_t>(n), normal};
      changed = true;
      continue;
    }
    if (slot < 0) continue;
    const NodeSupport& held = previous_[static_cast<std::size_t>(slot)];
    const Eigen::Vector3d free_motion(free_m[3 * n] - start_m[3 * n],
                                      free_m[3 * n + 1] - start_m[3 * n + 1],
                                      free_m[3 * n + 2] - start_m[3 * n + 2]);
    if (held.normal.dot(free_motion) > kLiftOffM || !free_motion.allFinite()) {
      changed = true;  // lifts off: the spring would pull it back
      continue;
    }
    supports_[count_++] = held;
  }
  for (std::size_t i = 0; i < previous_count; ++i) slot_of_node_[previous_[i].node] = -1;
  return changed;
}

}  // namespace fahr::fem
