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

ObstacleSupport::ObstacleSupport(std::size_t node_count, std::size_t tet_count)
    : supports_(node_count),
      previous_(node_count),
      slot_of_node_(node_count, -1),
      tets_(tet_count),
      previous_tets_(tet_count),
      slot_of_tet_(tet_count, -1) {}

bool ObstacleSupport::clear() {
  const bool had = count_ > 0 || tet_count_ > 0;
  count_ = 0;
  tet_count_ = 0;
  return had;
}

namespace {

double dot12(const std::array<Eigen::Vector3d, 4>& a, const std::array<Eigen::Vector3d, 4>& b) {
  return a[0].dot(b[0]) + a[1].dot(b[1]) + a[2].dot(b[2]) + a[3].dot(b[3]);
}

}  // namespace

bool ObstacleSupport::update(const ObstacleProjection* anatomy, const VolumeFloor* floor,
                             std::span<const double> start_m, std::span<const double> free_m) {
  const std::size_t previous_count = count_;
  std::copy_n(supports_.begin(), previous_count, previous_.begin());
  for (std::size_t i = 0; i < previous_count; ++i)
    slot_of_node_[previous_[i].node] = static_cast<std::int32_t>(i);
  const std::size_t nodes = std::min({anatomy == nullptr ? supports_.size() : anatomy->node_count(),
                                      supports_.size(), start_m.size() / 3, free_m.size() / 3});
  bool changed = false;
  count_ = 0;
  // Node order, so the set (and A) does not depend on the order of moves.
  for (std::size_t n = 0; n < nodes; ++n) {
    const std::int32_t slot = slot_of_node_[n];
    if (anatomy != nullptr && anatomy->moved(n)) {
      const Eigen::Vector3d& normal = anatomy->move_normal(n);
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
  return update_tets(floor, start_m, free_m) || changed;
}

// The floor's tets, as the nodes above: held from the step after the floor
// moved them, along the direction it moved them; let go when the free
// motion opens them, and all of them when there is no floor (none in the
// step: nothing presses the body).
bool ObstacleSupport::update_tets(const VolumeFloor* floor, std::span<const double> start_m,
                                  std::span<const double> free_m) {
  const std::size_t previous_count = tet_count_;
  std::copy_n(tets_.begin(), previous_count, previous_tets_.begin());
  for (std::size_t i = 0; i < previous_count; ++i)
    slot_of_tet_[previous_tets_[i].tet] = static_cast<std::int32_t>(i);
  bool changed = false;
  tet_count_ = 0;
  const std::size_t tets = floor == nullptr ? 0 : std::min(floor->tet_count(), tets_.size());
  const std::vector<Tet>* rest_tets = floor == nullptr ? nullptr : &floor->tets();
  for (std::size_t e = 0; e < tets_.size(); ++e) {
    const std::int32_t slot = slot_of_tet_[e];
    if (e < tets && floor->moved(e)) {
      const std::array<Eigen::Vector3d, 4>& direction = floor->direction(e);
      if (slot >= 0 && dot12(previous_tets_[static_cast<std::size_t>(slot)].direction, direction) >=
                           kSameNormalCos) {
        tets_[tet_count_++] = previous_tets_[static_cast<std::size_t>(slot)];
        continue;
      }
      tets_[tet_count_++] = TetSupport{static_cast<std::uint32_t>(e), direction};
      changed = true;
      continue;
    }
    if (slot < 0) continue;
    const TetSupport& held = previous_tets_[static_cast<std::size_t>(slot)];
    double opening = 0.0;  // the free motion along the held direction
    bool finite = true;
    if (rest_tets != nullptr) {
      const Tet& tet = (*rest_tets)[e];
      for (int a = 0; a < 4; ++a) {
        const std::size_t n = tet[static_cast<std::size_t>(a)];
        const Eigen::Vector3d free_motion(free_m[3 * n] - start_m[3 * n],
                                          free_m[3 * n + 1] - start_m[3 * n + 1],
                                          free_m[3 * n + 2] - start_m[3 * n + 2]);
        finite = finite && free_motion.allFinite();
        opening += held.direction[static_cast<std::size_t>(a)].dot(free_motion);
      }
    }
    if (rest_tets == nullptr || opening > kLiftOffM || !finite) {
      changed = true;  // opens, or no floor any more: the spring would pull
      continue;
    }
    tets_[tet_count_++] = held;
  }
  for (std::size_t i = 0; i < previous_count; ++i) slot_of_tet_[previous_tets_[i].tet] = -1;
  return changed;
}

}  // namespace fahr::fem
