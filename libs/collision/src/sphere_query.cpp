// Spheres against a rigid body's signed distance field (see sphere_query.h).
#include "fahr/collision/sphere_query.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "fahr/geometry/closest_point.h"

namespace fahr::collision {
namespace {

// Bound of |grid - true distance| in cells. The grid value is a convex
// combination of exact corner distances, each within |x_i - p| of the true
// distance at p (a distance is 1-Lipschitz), so the error is at most
// sum_i w_i |x_i - p| <= sqrt(sum_i w_i |x_i - p|^2) = h sqrt(sum_axes f (1 - f))
// <= h sqrt(3) / 2, with f the fractional position per axis.
constexpr double kGridErrorCells = 0.8660254037844386;
// Below this |c - q| (m) the direction is numerically meaningless: the
// field's own normal is used instead.
constexpr double kMinNormalLength = 1e-9;
// Relative slack on a search bound, so rounding never drops the true nearest triangle.
constexpr double kBoundSlack = 1e-9;
// Absolute slack of a search bound, m: a hint exactly on the surface gives a
// bound of 0 for a point on it.
constexpr double kBoundFloorM = 1e-12;
// Slack of a decision the query takes from a bound instead of a grid read
// (remember a leaf's spheres without reading at their centres), m: it must
// never be taken where the reads would have decided otherwise, so rounding
// of the bound's arithmetic (~1e-19 m at these sizes) is paid for many
// times over.
constexpr double kDecisionSlackM = 1e-9;

struct Frame {
  Eigen::Matrix3d body_from_world_rotation;
  Eigen::Vector3d body_from_world_translation;
  Eigen::Vector3d to_body(const Eigen::Vector3d& p) const {
    return body_from_world_rotation * p + body_from_world_translation;
  }
};

// The grid a query reads: the body's FieldGrid when it has one, else the
// field's own. `error_m` bounds |value - true distance| (see kGridErrorCells).
struct Grid {
  const geometry::SignedDistanceField& sdf;
  const FieldGrid* copy;
  double error_m;
  double distance(const Eigen::Vector3d& p) const noexcept {
    return copy != nullptr ? copy->distance(p) : sdf.grid_distance(p);
  }
};

// The sample of the grid at p from its value and gradient there: the
// nearest point along the gradient.
geometry::SdfSample from_gradient(const Eigen::Vector3d& p, double distance,
                                  const Eigen::Vector3d& gradient) noexcept {
  geometry::SdfSample s;
  s.distance_m = distance;
  const double norm = gradient.norm();
  s.normal = norm > 0.0 ? Eigen::Vector3d(gradient / norm) : Eigen::Vector3d::UnitZ();
  s.closest_point_m = p - distance * s.normal;
  return s;
}

// The grid alone: trilinear distance, its gradient, the nearest point along
// it. From a FieldGrid the gradient is the interpolant's in p's cell (the same
// 8 corners as the value); from the field, central differences over half a
// cell (6 more trilinear reads).
// gradient_length: the length of the gradient (1 where the field is one
// plane's distance over the cells read).
geometry::SdfSample grid_sample(const Grid& grid, const Eigen::Vector3d& p, double distance,
                                double& gradient_length) noexcept {
  Eigen::Vector3d gradient;
  if (grid.copy != nullptr) {
    distance = grid.copy->distance_gradient(p, gradient);
    gradient_length = gradient.norm();
  } else {
    const double h = 0.5 * grid.sdf.cell_size_m();
    for (int axis = 0; axis < 3; ++axis) {
      const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(axis);
      gradient[axis] = grid.sdf.grid_distance(p + step) - grid.sdf.grid_distance(p - step);
    }
    gradient_length = gradient.norm() / (2.0 * h);
  }
  return from_gradient(p, distance, gradient);
}

// The exact nearest point, searched only within `bound` (m, >= the true
// distance), the sign from the grid (certain: the caller passes only points
// where |grid| exceeds the grid's error). Cheaper than the field's own
// queries: the field bounds its search by |grid| + sqrt(3) cells, or not at
// all beyond its band, and a search ball of 1-2 mm on the finely tessellated
// blade tests hundreds of triangles.
geometry::SdfSample bounded_exact(const geometry::SignedDistanceField& sdf,
                                  const Eigen::Vector3d& p, double grid, double bound) noexcept {
  const double reach = bound * (1.0 + kBoundSlack) + kBoundFloorM;
  const geometry::BvhClosestPoint hit = sdf.bvh().closest_point(p, reach * reach);
  if (hit.triangle < 0) return sdf.query_exact(p);  // rounding at the bound: search everything
  geometry::SdfSample s;
  const double distance = std::sqrt(hit.distance_squared);
  const double sign = grid < 0.0 ? -1.0 : 1.0;
  s.distance_m = sign * distance;
  s.closest_point_m = hit.point;
  s.normal = distance > kMinNormalLength ? Eigen::Vector3d(sign * (p - hit.point) / distance)
                                         : Eigen::Vector3d::UnitZ();
  s.exact = true;
  return s;
}

// hint: a point of the body's surface (body frame) or null; |p - hint| bounds
// the distance from above.
geometry::SdfSample sample(const Grid& field, const Eigen::Vector3d& p, double grid,
                           const QuerySettings& settings, const Eigen::Vector3d* hint) noexcept {
  const geometry::SignedDistanceField& sdf = field.sdf;
  const double grid_error = field.error_m;
  double gradient_length = 0.0;
  if (!settings.exact_narrow_phase) return grid_sample(field, p, grid, gradient_length);
  // Too near the surface for the grid's sign: the field's pseudo-normal test.
  if (!(std::abs(grid) > grid_error)) return sdf.query(p);
  if (settings.flat_gradient_tolerance > 0.0) {
    geometry::SdfSample s = grid_sample(field, p, grid, gradient_length);
    if (std::abs(gradient_length - 1.0) <= settings.flat_gradient_tolerance) {
      return s;  // one plane's distance: trilinear interpolation reproduces it
    }
  }
  double bound = std::abs(grid) + grid_error;
  if (hint != nullptr) bound = std::min(bound, (p - *hint).norm());
  return bounded_exact(sdf, p, grid, bound);
}

// The contact of a sphere whose centre is outside (s.distance_m > 0): it is
// its own pre-penetration centre. complete_deferred() calls it too, so a
// deferred contact gets the same numbers.
void outside_contact(const Eigen::Vector3d& centre_body, double radius,
                     const geometry::SdfSample& s, Eigen::Vector3d& q, Eigen::Vector3d& n,
                     double& depth) noexcept {
  q = s.closest_point_m;
  const Eigen::Vector3d d = centre_body - q;
  const double len = d.norm();
  n = len > kMinNormalLength ? Eigen::Vector3d(d / len) : s.normal;
  depth = radius - s.distance_m;
}

// The surface point of a reported sphere and its depth behind the body's
// tangent plane at the contact (NaN x: no anchor): no field read, and the
// side is the pre-penetration normal's, so a point pushed past a thin
// plate's mid-plane is still measured from the face it came through.
void probe_surface(const SphereTree& tree, std::uint32_t slot, QuerySettings::SurfaceProbe probe,
                   SphereContact& contact) noexcept {
  if (probe == QuerySettings::SurfaceProbe::kNone) return;
  const Eigen::Vector3d& anchor = tree.slot_anchors()[slot];
  if (std::isnan(anchor.x())) return;
  const auto& face = tree.slot_faces()[slot];
  contact.surface_point_m =
      probe == QuerySettings::SurfaceProbe::kFacePoint
          ? geometry::closest_point_on_triangle(contact.point_m, face[0], face[1], face[2]).point
          : anchor;
  contact.surface_depth_m = (contact.point_m - contact.surface_point_m).dot(contact.normal);
  contact.has_surface = true;
}

// The contact of one sphere whose exact sample at its centre is `s`.
bool narrow_phase(const Grid& field, const Eigen::Vector3d* hint, double margin,
                  const Eigen::Vector3d& centre_body, double radius, const geometry::SdfSample& s,
                  const QuerySettings& settings, const PrePenetrationMemory& memory,
                  std::uint32_t slot, std::uint64_t query, Eigen::Vector3d& q, Eigen::Vector3d& n,
                  double& depth, bool& no_history) noexcept {
  no_history = false;
  if (s.distance_m > 0.0) {
    outside_contact(centre_body, radius, s, q, n, depth);
    return depth > -margin;
  }
  Eigen::Vector3d before;
  if (memory.recall(slot, query, settings.max_memory_age, before)) {
    // The grid narrow phase with a FieldGrid reads value and gradient in one
    // go (grid_sample ignores the value passed): no separate read first.
    const bool one_read = field.copy != nullptr && !settings.exact_narrow_phase;
    const geometry::SdfSample b =
        sample(field, before, one_read ? 0.0 : field.distance(before), settings, hint);
    q = b.closest_point_m;
    const Eigen::Vector3d d = before - q;
    const double len = d.norm();
    n = len > kMinNormalLength ? Eigen::Vector3d(d / len) : b.normal;
    depth = radius - (centre_body - q).dot(n);
    return depth > -margin;
  }
  no_history = true;
  q = s.closest_point_m;
  n = s.normal;
  depth = radius - s.distance_m;
  return depth > -margin;
}

}  // namespace

QueryStats query_spheres(const SphereTree& tree, const SphereState& state, const RigidBody& body,
                         const QuerySettings& settings, PrePenetrationMemory& memory,
                         ContactBuffer& out) noexcept {
  QueryStats stats;
  const auto& nodes = tree.nodes();
  if (nodes.empty() || tree.order().empty() || body.sdf == nullptr) return stats;
  const geometry::SignedDistanceField& sdf = *body.sdf;
  // The broad phase and the leaf test read the copy in both narrow phases;
  // the exact one still searches the triangles (and near the surface asks the
  // field itself), so its contacts do not change.
  const FieldGrid* copy = body.grid != nullptr && !body.grid->empty() ? body.grid : nullptr;
  const double grid_error =
      kGridErrorCells * sdf.cell_size_m() + (copy != nullptr ? copy->storage_error_m() : 0.0);
  const Grid field{sdf, copy, grid_error};
  const Eigen::Isometry3d body_from_world = body.world_from_body.inverse();
  const Frame frame{body_from_world.linear(), body_from_world.translation()};
  const Eigen::Matrix3d world_rotation = body.world_from_body.linear();
  const std::uint64_t query = memory.next_query();
  const auto& slots = tree.slot_spheres();
  const auto& order = tree.order();
  // With a FieldGrid and the grid narrow phase one read gives the value
  // and, only for the spheres that reach the narrow phase, the gradient.
  const bool one_read = copy != nullptr && !settings.exact_narrow_phase;
  const bool defer = one_read && settings.defer_outside_contacts;
  if (slots.size() != state.centres_m().size()) return stats;  // a tree of another layout

  // The grid's interpolant is L-Lipschitz, L = sqrt(3) (1 + 2 e / h) + 1:
  // each axis's slope is a blend of edge differences of exact distances,
  // each within a cell plus twice the storage error e; beyond the grid the
  // clamp adds slope 1. The sphere floors below
  // (PrePenetrationMemory::remember) use it.
  // Between two points both on the grid (a box, so the segment is too) the
  // clamp's slope does not enter: L = sqrt(3) (1 + 2 e / h).
  const double storage_error = copy != nullptr ? copy->storage_error_m() : 0.0;
  const double lipschitz_on_grid = std::sqrt(3.0) * (1.0 + 2.0 * storage_error / sdf.cell_size_m());
  const double lipschitz = lipschitz_on_grid + 1.0;
  // What a decision taken from the grid (or a floor of it) must leave for
  // the grid's error. The exact narrow phase decides on the true distance,
  // within grid_error of the grid. The grid narrow phase's contacts are the
  // grid's own values (a contact is r - grid > -margin): a floor of the grid
  // decides them with nothing to spare.
  const double decision_error = settings.exact_narrow_phase ? grid_error : 0.0;

  // Lower bound of the grid value at any point of a node's spheres (grown by
  // the skin and the candidate margin), m. On the grid: the grid at the box's
  // middle less the node's reach (a distance is 1-Lipschitz), less the grid's
  // error twice (the grid is within it of the distance at the middle and at
  // the sphere). Off the grid the field extends its border value by the
  // distance to the border, which can exceed the distance; there the bound is
  // the distance to the surface's box, which the grid surrounds by at least
  // the exact band plus two cells (SignedDistanceField), less one error.
  const Eigen::Vector3d grid_low = sdf.grid_origin_m();
  const Eigen::Vector3d grid_high =
      grid_low +
      sdf.cell_size_m() * (sdf.grid_dimensions() - Eigen::Vector3i::Ones()).cast<double>();
  const Eigen::Vector3d inset = Eigen::Vector3d::Constant(sdf.band_m() + 2.0 * sdf.cell_size_m());
  const Eigen::Vector3d surface_low = grid_low + inset;
  const Eigen::Vector3d surface_high = grid_high - inset;
  auto on_grid = [&](const Eigen::Vector3d& p) noexcept {
    return (p.array() >= grid_low.array()).all() && (p.array() <= grid_high.array()).all();
  };
  auto node_middle = [&](const SphereTreeNode& node) noexcept {
    return frame.to_body(0.5 * (node.box_min_m + node.box_max_m));
  };
  auto bound_at = [&](const SphereTreeNode& node, const Eigen::Vector3d& middle) noexcept {
    const double reach = node.reach_m + settings.contact_skin_m + settings.candidate_margin_m;
    if (on_grid(middle)) return field.distance(middle) - 2.0 * grid_error - reach;
    const double to_surface_box =
        (middle - middle.cwiseMax(surface_low).cwiseMin(surface_high)).norm();
    return to_surface_box - grid_error - reach;  // a NaN pose gives NaN: the caller prunes it
  };
  auto node_bound = [&](const SphereTreeNode& node) noexcept {
    return bound_at(node, node_middle(node));
  };
  // The deepest k contacts found so far, as a min-heap of depths (deepest_only).
  const std::size_t keep = std::min(settings.deepest_only, kMaxDeepest);
  // Only [0, kept) is ever read; zeroing its 2 KB on every query would be waste in the tick.
  // NOLINTNEXTLINE(cppcoreguidelines-pro-type-member-init): filled before read, as above
  std::array<double, kMaxDeepest> kept_depths;
  std::size_t kept = 0;
  const auto deeper_first = [](double a, double b) { return a > b; };  // min-heap
  auto note_depth = [&](double depth) noexcept {
    if (keep == 0) return;
    if (kept < keep) {
      kept_depths[kept++] = depth;
      std::push_heap(kept_depths.begin(), kept_depths.begin() + static_cast<std::ptrdiff_t>(kept),
                     deeper_first);
    } else if (depth > kept_depths[0]) {
      std::pop_heap(kept_depths.begin(), kept_depths.begin() + static_cast<std::ptrdiff_t>(kept),
                    deeper_first);
      kept_depths[kept - 1] = depth;
      std::push_heap(kept_depths.begin(), kept_depths.begin() + static_cast<std::ptrdiff_t>(kept),
                     deeper_first);
    }
  };
  // Every sphere of a leaf in the body frame first, each one's grid cell
  // asked for at once: with the grid cold (the haptic tick after a FEM step
  // in one process, or after other processes), the 16 reads overlap instead
  // of waiting on memory one after another (aist_bench replay --evict-kb
  // 65536: -25 % median; warm, with the lines in cache, it costs ~10 %).
  std::array<Eigen::Vector3d, SphereTree::kLeafSize> leaf_body;
  auto load_leaf = [&](const SphereTreeNode& node) noexcept {
    const auto count =
        static_cast<std::size_t>(std::min<std::int32_t>(node.count, SphereTree::kLeafSize));
    for (std::size_t k = 0; k < count; ++k) {
      leaf_body[k] = frame.to_body(slots[static_cast<std::size_t>(node.first) + k].head<3>());
    }
    return count;
  };
  // The grid read at a sphere decides first whether grid - decision_error >
  // r + candidate margin (then it is only remembered). Its memory's floor of
  // the grid at the centre it last remembered decides that without the
  // read when floor - L |p - centre| is still beyond it. No square root unless
  // the read is skipped: the new floor needs it.
  std::array<double, SphereTree::kLeafSize>
      leaf_floor{};  // new floor of a sphere whose read is skipped, else NaN
  auto bound_leaf = [&](const SphereTreeNode& node, std::size_t count) noexcept {
    for (std::size_t k = 0; k < count; ++k) {
      const auto slot = static_cast<std::uint32_t>(node.first) + static_cast<std::uint32_t>(k);
      const double r = slots[slot][3] + settings.contact_skin_m;
      const double spare =
          memory.grid_floor_m(slot) - decision_error - r - settings.candidate_margin_m;
      const Eigen::Vector3d& last = memory.last_centre_body_m(slot);
      const double moved_squared = (leaf_body[k] - last).squaredNorm();
      const double slope = on_grid(leaf_body[k]) && on_grid(last) ? lipschitz_on_grid : lipschitz;
      if (spare > 0.0 && spare * spare > slope * slope * moved_squared) {
        leaf_floor[k] = memory.grid_floor_m(slot) - slope * std::sqrt(moved_squared);
      } else {
        leaf_floor[k] = std::numeric_limits<double>::quiet_NaN();
        if (copy != nullptr) copy->prefetch(leaf_body[k]);
      }
    }
  };
  // A leaf whose bound proves every centre outside, with its margin to
  // spare: each sphere would pass the leaf test's first check (grid -
  // decision_error > r + candidate margin) and only be remembered, so it is
  // remembered without its grid read (and its cells are not prefetched:
  // lines nobody reads only evict others). The same memory and contacts as testing it.
  // The floor it leaves: the grid at a sphere is at least the bound + r +
  // candidate margin (|c - middle| + r <= reach, the bound's derivation).
  auto remember_leaf = [&](const SphereTreeNode& node, double bound) noexcept {
    const std::size_t count = load_leaf(node);
    for (std::size_t k = 0; k < count; ++k) {
      const auto slot = static_cast<std::uint32_t>(node.first) + static_cast<std::uint32_t>(k);
      const double r = slots[slot][3] + settings.contact_skin_m;
      memory.remember(slot, leaf_body[k], query, bound + r + settings.candidate_margin_m);
    }
    stats.spheres_remembered += static_cast<std::uint32_t>(count);
  };
  auto test_leaf = [&](const SphereTreeNode& node) noexcept {
    // The floors are read before any grid cell can be asked for: their lines
    // are asked for at once, so a cold leaf waits on memory once, not once
    // per line. (The stack walk asked for them already, when the leaf
    // passed its bound; asking before the bound was read was slower: most
    // leaves whose bound is read are pruned.)
    memory.prefetch_leaf(static_cast<std::uint32_t>(node.first),
                         static_cast<std::uint32_t>(node.count));
    const std::size_t count = load_leaf(node);
    bound_leaf(node, count);
    for (std::size_t k = 0; k < count; ++k) {
      const std::uint32_t sphere = order[static_cast<std::size_t>(node.first) + k];
      // The memory is kept by slot (leaf order): read in sequence, not at random.
      const auto slot = static_cast<std::uint32_t>(node.first) + static_cast<std::uint32_t>(k);
      const Eigen::Vector3d& p = leaf_body[k];
      const double r = slots[slot][3] + settings.contact_skin_m;
      if (!std::isnan(leaf_floor[k])) {
        // The read would find grid - error > r + margin: remembered, as then.
        memory.remember(slot, p, query, leaf_floor[k]);
        ++stats.spheres_bounded;
        continue;
      }
      ++stats.spheres_tested;
      FieldGrid::Read cell;
      if (one_read) cell = copy->read(p);
      const double grid = one_read ? cell.value : field.distance(p);
      if (grid - decision_error > r + settings.candidate_margin_m) {
        memory.remember(slot, p, query, grid);  // outside: grid - error > r > 0
        continue;
      }
      // The grid narrow phase's distance is this read: with the centre
      // outside and the depth r - grid not within the candidate margin, the
      // narrow phase would only remember the centre and report nothing. Its
      // normal (a square root and three divisions) is not worked out for that.
      if (!settings.exact_narrow_phase && grid > 0.0 &&
          !(r - grid > -settings.candidate_margin_m)) {
        memory.remember(slot, p, query, grid);
        continue;
      }
      ++stats.exact_queries;
      if (defer && grid > 0.0) {
        // Outside and within the candidate margin (the test above): the
        // narrow phase's depth is r - grid; the rest waits for
        // complete_deferred(), which only the kept contacts reach.
        memory.remember(slot, p, query, grid);
        ++stats.contacts;
        SphereContact contact;
        contact.sphere_id = sphere;
        contact.body_id = body.id;
        contact.depth_m = r - grid;
        contact.candidate = contact.depth_m <= 0.0;
        contact.deferred = true;
        contact.slot = slot;
        if (!out.push(contact)) stats.overflowed = true;
        note_depth(contact.depth_m);
        continue;
      }
      Eigen::Vector3d last_nearest;
      // Only the exact search uses the hint: the grid narrow phase does not read it.
      const Eigen::Vector3d* hint =
          settings.exact_narrow_phase && memory.recall_nearest(slot, last_nearest) ? &last_nearest
                                                                                   : nullptr;
      const geometry::SdfSample s = one_read ? from_gradient(p, grid, copy->gradient(cell))
                                             : sample(field, p, grid, settings, hint);
      if (s.distance_m > 0.0) memory.remember(slot, p, query, grid);
      if (!(s.distance_m > 0.0)) ++stats.spheres_inside;
      if (s.exact) memory.remember_nearest(slot, s.closest_point_m);
      Eigen::Vector3d q, n;
      double depth = 0.0;
      bool no_history = false;
      if (!narrow_phase(field, hint, settings.candidate_margin_m, p, r, s, settings, memory, slot,
                        query, q, n, depth, no_history)) {
        continue;
      }
      ++stats.contacts;
      SphereContact contact;
      contact.sphere_id = sphere;
      contact.body_id = body.id;
      contact.point_m = body.world_from_body * q;
      contact.normal = world_rotation * n;
      contact.depth_m = depth;
      contact.normal_without_history = no_history;
      contact.candidate = depth <= 0.0;
      contact.slot = slot;
      probe_surface(tree, slot, settings.surface_probe, contact);
      if (!out.push(contact)) stats.overflowed = true;
      note_depth(depth);
    }
  };

  if (keep == 0) {
    // A node's bound is worked out when its parent passes, both children's
    // at once: their grid cells are asked for together, and a child that
    // passes has its own children's boxes (or, a leaf, its spheres and
    // memory) asked for when it is pushed, long before it is popped. On a
    // cold cache the walk otherwise waits on a box, then on its grid cell,
    // node after node. The nodes that pass are popped in the same order
    // (right child first) as when each bound was read at its pop.
    struct Pending {
      std::int32_t node;
      double bound_m;
    };
    std::array<Pending, SphereTree::kMaxDepth + 1> stack{};
    int top = 0;
    auto passes = [&](double bound) noexcept {
      return bound <= settings.approach_margin_m;
    };  // NaN: pruned
    auto push = [&](std::int32_t index, double bound) noexcept {
      const SphereTreeNode& node = nodes[static_cast<std::size_t>(index)];
      if (node.count == 0) {
        // Both children share two lines.
        __builtin_prefetch(&nodes[static_cast<std::size_t>(node.first)]);
        __builtin_prefetch(&nodes[static_cast<std::size_t>(node.first) + 1]);
      } else {
        const auto first = static_cast<std::size_t>(node.first);
        const std::size_t end =
            std::min(slots.size(), first + static_cast<std::size_t>(node.count));
        for (std::size_t slot = first; slot < end; slot += 2) __builtin_prefetch(&slots[slot]);
        memory.prefetch_leaf(static_cast<std::uint32_t>(node.first),
                             static_cast<std::uint32_t>(node.count));
      }
      stack[top++] = {index, bound};
    };
    ++stats.nodes_visited;
    const double root_bound = node_bound(nodes[0]);
    if (!passes(root_bound)) {
      stats.body_skipped = true;
      return stats;
    }
    push(0, root_bound);
    while (top > 0) {
      const Pending next = stack[--top];
      const SphereTreeNode& node = nodes[static_cast<std::size_t>(next.node)];
      if (node.count == 0) {
        const SphereTreeNode& left = nodes[static_cast<std::size_t>(node.first)];
        const SphereTreeNode& right = nodes[static_cast<std::size_t>(node.first) + 1];
        const Eigen::Vector3d left_middle = node_middle(left);
        const Eigen::Vector3d right_middle = node_middle(right);
        if (copy != nullptr) {
          copy->prefetch(left_middle);
          copy->prefetch(right_middle);
        }
        const double left_bound = bound_at(left, left_middle);
        const double right_bound = bound_at(right, right_middle);
        stats.nodes_visited += 2;
        if (passes(left_bound)) push(node.first, left_bound);
        if (passes(right_bound)) push(node.first + 1, right_bound);
        continue;
      }
      // bound - decision_error > 0: every centre is outside by more than its
      // radius, the skin and the candidate margin plus the sphere test's own
      // error (none in the grid narrow phase).
      if (next.bound_m - decision_error > kDecisionSlackM) {
        remember_leaf(node, next.bound_m);
      } else {
        test_leaf(node);
      }
    }
    return stats;
  }

  // Deepest first: the frontier is a heap on the bound (the smallest, i.e.
  // the deepest a sphere in it can be, on top). A sphere of a node with bound
  // b reads at most -b - margin deep: its depth r + skin - grid(c) is at most
  // reach + skin - grid(middle) + 2 grid error, as |c - middle| + r <= reach.
  std::vector<PrePenetrationMemory::Frontier>& frontier = memory.frontier();
  frontier.clear();
  if (frontier.capacity() <
      nodes.size()) {  // a memory of another tree (or a copy): never allocate here
    stats.overflowed = true;
    return stats;
  }
  const auto nearer_first = [](const PrePenetrationMemory::Frontier& a,
                               const PrePenetrationMemory::Frontier& b) {
    return a.bound_m > b.bound_m;
  };
  auto offer_node = [&](std::int32_t index) noexcept {
    const double bound = node_bound(nodes[static_cast<std::size_t>(index)]);
    ++stats.nodes_visited;
    if (!(bound <= settings.approach_margin_m)) {
      if (index == 0) stats.body_skipped = true;
      return;
    }
    frontier.push_back({bound, index});
    std::push_heap(frontier.begin(), frontier.end(), nearer_first);
  };
  offer_node(0);
  while (!frontier.empty()) {
    std::pop_heap(frontier.begin(), frontier.end(), nearer_first);
    const PrePenetrationMemory::Frontier next = frontier.back();
    frontier.pop_back();
    const SphereTreeNode& node = nodes[static_cast<std::size_t>(next.node)];
    if (kept == keep) {
      const double deepest_possible = -next.bound_m - settings.candidate_margin_m;
      if (kept_depths[0] >= deepest_possible) break;  // nothing left can beat the k kept
    }
    if (node.count == 0) {
      offer_node(node.first);
      offer_node(node.first + 1);
      continue;
    }
    test_leaf(node);
  }
  return stats;
}

void complete_deferred(const SphereTree& tree, const RigidBody& body, const QuerySettings& settings,
                       ContactBuffer& contacts, const std::uint32_t* indices,
                       std::size_t count) noexcept {
  if (body.grid == nullptr || body.grid->empty()) return;  // the query defers nothing without one
  const FieldGrid& copy = *body.grid;
  // The query's own frame and reads, step for step: the same numbers.
  const Eigen::Isometry3d body_from_world = body.world_from_body.inverse();
  const Frame frame{body_from_world.linear(), body_from_world.translation()};
  const Eigen::Matrix3d world_rotation = body.world_from_body.linear();
  const auto& slots = tree.slot_spheres();
  for (std::size_t i = 0; i < count; ++i) {
    SphereContact& contact = contacts[indices[i]];
    if (!contact.deferred || contact.slot >= slots.size()) continue;
    const Eigen::Vector4d& sphere = slots[contact.slot];
    const Eigen::Vector3d p = frame.to_body(sphere.head<3>());
    const FieldGrid::Read cell = copy.read(p);
    const geometry::SdfSample s = from_gradient(p, cell.value, copy.gradient(cell));
    Eigen::Vector3d q, n;
    double depth = 0.0;
    outside_contact(p, sphere[3] + settings.contact_skin_m, s, q, n, depth);
    contact.point_m = body.world_from_body * q;
    contact.normal = world_rotation * n;
    contact.deferred = false;
    probe_surface(tree, contact.slot, settings.surface_probe, contact);
  }
}

}  // namespace fahr::collision
