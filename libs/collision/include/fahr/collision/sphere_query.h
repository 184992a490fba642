// Spheres against a rigid body through its signed distance field: the broad
// phase walks the sphere tree and drops subtrees the body cannot touch (a
// lower bound on the distance from the field's grid); the narrow phase gives
// per sphere the nearest surface point q, the normal from the pre-penetration
// centre and the depth. Allocation-free and noexcept: the 1 kHz path.
//
// The pre-penetration centre (docs/design/contact-contract.md, n = (c - q)/|c - q|): while a
// sphere's centre is outside the body, it is its own pre-penetration centre
// and n is the field's outward normal. Once the centre is inside (a deep
// press, or a thin blade), the field's normal can point through the plate, so
// the normal comes from the centre's last position outside the body, kept per
// sphere in the body's frame (PrePenetrationMemory). The rest centre mapped
// into the body frame is not used: a blade that presses the tongue down has
// the rest tongue on its far side, so it would give the wrong side exactly
// when it matters. The previous state's centre is the one the trajectory last
// had outside, so it gives the side it came from.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "fahr/collision/contact_buffer.h"
#include "fahr/collision/rigid_body.h"
#include "fahr/collision/sphere_state.h"
#include "fahr/collision/sphere_tree.h"

namespace fahr::collision {

struct QuerySettings {
  // Spheres within this distance of the body are visited although they do not
  // touch it, so their centre outside is remembered before they penetrate, m,
  // >= 0. 1 mm is two ticks of a 0.5 m/s hand at 1 kHz.
  double approach_margin_m = 1e-3;
  // A remembered outside centre older than this many queries is not trusted
  // (the body may have come round from the other side), >= 1.
  std::uint64_t max_memory_age = 200;
  // true: the narrow phase asks the field for exact distances (a search of
  // the body's triangles, ~1-3 us each on the 19k-triangle blade). false: it
  // reads the field's grid only (trilinear distance, normal from its central
  // differences, q = p - d n), ~0.1 us, exact where the surface is flat
  // within a cell and off by a fraction of a cell at edges.
  bool exact_narrow_phase = true;
  // With exact_narrow_phase, an approximation, off by default (0): the
  // triangle search is skipped where the grid's central-difference gradient
  // has unit length within this (the field looks like one plane's distance
  // over the cells read). It is not a proof: outside a convex edge or a
  // curved face the gradient also has unit length while trilinear
  // interpolation is off by about h^2 / (8 rho) (h the cell, rho the distance
  // to the centre of curvature): ~3 um on a 5 mm ball with 0.5 mm cells
  // (query_test), and near the 1 mm plate of a box it flips contacts of a few
  // micrometres. >= 0.
  double flat_gradient_tolerance = 0.0;
  // Contact skin, m, >= 0: each sphere collides as if its radius were r +
  // skin. The union lies inside the surface by up to the coverage gap, so a
  // response that only clears the spheres leaves the real surface up to that
  // gap inside the tool; a skin of about the mean gap moves the union out to
  // the surface. The FEM side must then clear r + skin too.
  double contact_skin_m = 0.0;
  // Candidates, m, >= 0: spheres within this gap of the body (depth in
  // (-margin, 0]) are reported too, flagged candidate (contact contract: near, not
  // touching; the contact solve wants their compliance, and a response that
  // has just cleared a sphere leaves it at depth 0, still resting on the tool).
  double candidate_margin_m = 0.0;
  // 0: every contact. k > 0 (at most kMaxDeepest): the caller keeps only the
  // k deepest (the haptic tick's rows), so the tree is walked deepest-first,
  // by each subtree's bound on how deep a sphere in it can be, and the walk
  // stops once k contacts are found that no unvisited subtree can beat. The
  // k deepest are then among the contacts reported (more may be). A blade
  // pressed into the tongue touches ~500 spheres, of which 64 are kept.
  // Approximation: a sphere whose depth comes from its pre-penetration centre
  // (pushed through a thin blade) can be deeper than its subtree's bound,
  // which reads the field; such a sphere may be missed when k others beat the
  // bound. Spheres not visited are not remembered outside in that query.
  std::size_t deepest_only = 0;
  // Which point of the deformed surface measures a reported sphere
  // (SphereContact::surface_point_m, surface_depth_m): kFacePoint: the point
  // of its anchor's deformed face nearest the contact point (the surface
  // where the body touches; one closest point on a triangle); kAnchor: its
  // fixed anchor (sphere_layout::SurfaceAnchor). On aist_bench detection the fixed anchor
  // can lie ~1 mm from where a blade's rim cuts the face
  // (docs/design/aist-layout.md). kNone: no surface point (has_surface
  // false): for callers that use depth_m only (the haptic service's rows),
  // which then skip a face read and a closest point per reported sphere.
  enum class SurfaceProbe : std::uint8_t { kAnchor, kFacePoint, kNone };
  SurfaceProbe surface_probe = SurfaceProbe::kFacePoint;
  // Grid narrow phase with a FieldGrid only (else ignored): a contact whose
  // centre is outside the body is reported with its depth (r - grid, the
  // value the leaf test read) and flagged SphereContact::deferred; its
  // point, normal and surface point are worked out by complete_deferred()
  // for the contacts the caller keeps, the same numbers bit for bit. The
  // haptic tick keeps the 64 deepest of ~540 (a pressed blade with 1 mm
  // candidates), so most contacts need no gradient, normal or transform.
  // Contacts whose centre is inside are always complete: their depth comes
  // from the pre-penetration centre's own grid read.
  bool defer_outside_contacts = false;
};

// Most contacts QuerySettings::deepest_only can ask for.
inline constexpr std::size_t kMaxDeepest = 256;

// Per (sphere tree, rigid body): the last centre seen outside the body, in the
// body's frame. Capacity fixed at construction. Indexed by the sphere's slot
// in SphereTree::order(), not its id: the query visits spheres leaf by leaf,
// so memory kept by id (in separate arrays) cost cache misses at random
// (docs/design/aist-layout.md). A memory therefore belongs to one tree. The
// centre, its query index and a floor of the grid there, which every
// visited sphere writes, take 32 bytes, two spheres a cache line; the
// nearest point, which only the exact narrow phase reads, is kept apart.
class PrePenetrationMemory {
 public:
  PrePenetrationMemory() = default;
  explicit PrePenetrationMemory(std::size_t sphere_count)
      : slots_(sphere_count), nearest_(sphere_count) {
    frontier_.reserve(2 * sphere_count + 2);
  }
  // grid_floor_m: a lower bound of the grid's value at the centre (the value
  // read there, or what a bound proved without the read), m. The next query
  // reads no grid for a sphere whose floor, less the grid's Lipschitz bound
  // times how far the sphere has moved in the body frame since, still puts
  // it beyond its margins (the body moves ~0.1 mm a tick, the spheres only
  // when a FEM state arrives). Stored in single precision, rounded down.
  void remember(std::uint32_t slot, const Eigen::Vector3d& centre_body_m, std::uint64_t query,
                double grid_floor_m) noexcept {
    slots_[slot].centre_body_m = centre_body_m;
    slots_[slot].query_index = static_cast<std::uint32_t>(query);
    // Floors above kFloorCapM say no more than the cap (a floor may be
    // lower than the truth), and below it a float's rounding is under
    // kFloorRoundingM, taken off first so the stored floor never exceeds it.
    slots_[slot].grid_floor_m =
        static_cast<float>(std::min(grid_floor_m, kFloorCapM) - kFloorRoundingM);
  }
  // True and the centre when remembered within max_age queries of `query`.
  // The index is kept modulo 2^32 (next_query() skips 0): at 1 kHz a
  // memory older than 49 days could pass for a recent one.
  bool recall(std::uint32_t slot, std::uint64_t query, std::uint64_t max_age,
              Eigen::Vector3d& centre_body_m) const noexcept {
    const std::uint32_t when = slots_[slot].query_index;
    if (when == 0 || static_cast<std::uint32_t>(static_cast<std::uint32_t>(query) - when) > max_age)
      return false;
    centre_body_m = slots_[slot].centre_body_m;
    return true;
  }
  // The centre last remembered (any age; zero if never) and the floor of the
  // grid there (-inf if never), m.
  const Eigen::Vector3d& last_centre_body_m(std::uint32_t slot) const noexcept {
    return slots_[slot].centre_body_m;
  }
  double grid_floor_m(std::uint32_t slot) const noexcept { return slots_[slot].grid_floor_m; }
  // Drops every floor (the next query reads every sphere it tests): for a
  // body whose grid changed, and for tests that compare with and without.
  void forget_grid_floors() noexcept {
    for (Slot& s : slots_) s.grid_floor_m = -std::numeric_limits<float>::infinity();
  }
  // Asks the cache for the lines of `count` slots from `first` (no value changes).
  void prefetch_leaf(std::uint32_t first, std::uint32_t count) const noexcept {
    const std::size_t end = std::min<std::size_t>(slots_.size(), std::size_t{first} + count);
    for (std::size_t slot = first; slot < end; slot += 2) __builtin_prefetch(&slots_[slot]);
  }
  // The last nearest surface point found for a slot's sphere, body frame. Any point
  // of the rigid surface bounds the distance from above, however old, so the
  // exact search of the next query starts from |c - q_last| and visits only
  // the triangles that can beat it.
  void remember_nearest(std::uint32_t slot, const Eigen::Vector3d& point_body_m) noexcept {
    nearest_[slot].point_body_m = point_body_m;
    nearest_[slot].known = 1;
  }
  bool recall_nearest(std::uint32_t slot, Eigen::Vector3d& point_body_m) const noexcept {
    if (nearest_[slot].known == 0) return false;
    point_body_m = nearest_[slot].point_body_m;
    return true;
  }
  std::size_t size() const { return slots_.size(); }
  // 1-based; an index whose low 32 bits are 0 (never, in a slot) is skipped.
  std::uint64_t next_query() noexcept {
    if (static_cast<std::uint32_t>(++queries_) == 0) ++queries_;
    return queries_;
  }

  // Workspace of the deepest-first walk: subtrees to visit, keyed by their
  // distance bound. Sized at construction for any tree over these spheres
  // (a binary tree with at least one sphere per leaf has < 2n nodes).
  struct Frontier {
    double bound_m;
    std::int32_t node;
  };
  std::vector<Frontier>& frontier() noexcept { return frontier_; }

 private:
  static constexpr double kFloorCapM = 1.0;
  // > the rounding of a float below kFloorCapM (2^-24 m).
  static constexpr double kFloorRoundingM = 1e-7;
  struct alignas(32) Slot {
    Eigen::Vector3d centre_body_m = Eigen::Vector3d::Zero();
    std::uint32_t query_index = 0;  // low 32 bits, 0 never
    float grid_floor_m = -std::numeric_limits<float>::infinity();
  };
  struct Nearest {
    Eigen::Vector3d point_body_m = Eigen::Vector3d::Zero();
    std::uint8_t known = 0;
  };
  std::vector<Slot> slots_;
  std::vector<Nearest> nearest_;
  std::vector<Frontier> frontier_;
  std::uint64_t queries_ = 0;
};

struct QueryStats {
  std::uint32_t nodes_visited = 0;
  std::uint32_t spheres_tested = 0;  // reached the leaf test (read the grid at the centre)
  // Remembered outside without a test: their leaf's bound proved every
  // centre outside and no sphere of it within the candidate margin.
  std::uint32_t spheres_remembered = 0;
  // Remembered outside without a grid read: the floor their memory kept,
  // less how far they moved since, proved them beyond the candidate margin
  // (PrePenetrationMemory::remember). Not counted in spheres_tested.
  std::uint32_t spheres_bounded = 0;
  std::uint32_t exact_queries = 0;  // reached the narrow phase (exact or grid)
  std::uint32_t spheres_inside =
      0;  // of those, centre inside the body (depth from the pre-penetration centre)
  std::uint32_t contacts = 0;  // found (including those a full buffer dropped)
  bool body_skipped = false;   // the root could not touch the body
  bool overflowed = false;     // the buffer was full
};

// Appends the contacts of `state`'s spheres with `body` to `out` (not cleared).
// The centres and radii are read from the tree's copy (SphereTree::refit), so
// `tree` must have been refitted to `state`.
QueryStats query_spheres(const SphereTree& tree, const SphereState& state, const RigidBody& body,
                         const QuerySettings& settings, PrePenetrationMemory& memory,
                         ContactBuffer& out) noexcept;

// Completes the deferred contacts among contacts[indices[i]], i < count
// (QuerySettings::defer_outside_contacts; complete ones are left alone):
// point, normal and, with a surface probe, the surface point, as the query
// would have given them. `tree`, `body` and `settings` must be the query's,
// the tree not refitted since. Allocation-free.
void complete_deferred(const SphereTree& tree, const RigidBody& body, const QuerySettings& settings,
                       ContactBuffer& contacts, const std::uint32_t* indices,
                       std::size_t count) noexcept;

}  // namespace fahr::collision
