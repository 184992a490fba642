// Tool surface samples and their contacts with rigid anatomy (see
// surface_samples.h).
#include "fahr/collision/surface_samples.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>

namespace fahr::collision {
namespace {

// Error bound of the field's trilinear grid distance: sqrt(3) cells (the
// field's own bound, libs/geometry). Pruning subtracts it so no node
// that may touch is dropped.
constexpr double kGridErrorCells = 1.7320508075688772;

struct CubeKey {
  std::int64_t i, j, k;
  bool operator==(const CubeKey&) const = default;
};
struct CubeKeyHash {
  std::size_t operator()(const CubeKey& c) const noexcept {
    const auto u = static_cast<std::uint64_t>(c.i) * 73856093u ^
                   static_cast<std::uint64_t>(c.j) * 19349663u ^
                   static_cast<std::uint64_t>(c.k) * 83492791u;
    return static_cast<std::size_t>(u);
  }
};

}  // namespace

SurfaceSamples::SurfaceSamples(const geometry::SurfaceMesh& surface,
                               const SurfaceSampleSettings& settings) {
  if (surface.triangle_count() == 0)
    throw std::invalid_argument("surface samples: the surface has no triangles");
  if (!(settings.spacing_m > 0.0) || !std::isfinite(settings.spacing_m)) {
    throw std::invalid_argument("surface samples: spacing_m must be finite and > 0, got " +
                                std::to_string(settings.spacing_m));
  }
  if (settings.leaf_size < 1) {
    throw std::invalid_argument("surface samples: leaf_size must be >= 1, got " +
                                std::to_string(settings.leaf_size));
  }
  const double h = settings.spacing_m;
  // Per cube, the candidate nearest its centre: deterministic whatever the
  // triangle order, since ties are broken by the point's coordinates.
  std::unordered_map<CubeKey, Eigen::Vector3d, CubeKeyHash> best;
  const auto offer = [&](const Eigen::Vector3d& p) {
    const Eigen::Vector3d u = p / h;
    const CubeKey key{static_cast<std::int64_t>(std::floor(u.x())),
                      static_cast<std::int64_t>(std::floor(u.y())),
                      static_cast<std::int64_t>(std::floor(u.z()))};
    const Eigen::Vector3d centre =
        h * (Eigen::Vector3d(static_cast<double>(key.i), static_cast<double>(key.j),
                             static_cast<double>(key.k)) +
             Eigen::Vector3d::Constant(0.5));
    auto [it, inserted] = best.try_emplace(key, p);
    if (inserted) return;
    const double d_new = (p - centre).squaredNorm();
    const double d_old = (it->second - centre).squaredNorm();
    if (d_new < d_old ||
        (d_new == d_old && std::tie(p.x(), p.y(), p.z()) <
                               std::tie(it->second.x(), it->second.y(), it->second.z()))) {
      it->second = p;
    }
  };
  const auto& v = surface.vertices();
  for (const auto& t : surface.triangles()) {
    const Eigen::Vector3d& a = v[t[0]];
    const Eigen::Vector3d& b = v[t[1]];
    const Eigen::Vector3d& c = v[t[2]];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int n = std::max(1, static_cast<int>(std::ceil(longest / h)));
    if (static_cast<std::size_t>(n) * static_cast<std::size_t>(n) > settings.max_samples) {
      throw std::invalid_argument("surface samples: a triangle of " + std::to_string(longest) +
                                  " m would need more than max_samples samples at spacing_m " +
                                  std::to_string(h));
    }
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j) {
        offer(a + (b - a) * (static_cast<double>(i) / n) + (c - a) * (static_cast<double>(j) / n));
      }
    }
    if (best.size() > settings.max_samples) {
      throw std::invalid_argument("surface samples: more than max_samples (" +
                                  std::to_string(settings.max_samples) + ") samples at spacing_m " +
                                  std::to_string(h));
    }
  }
  points_m_.reserve(best.size());
  for (const auto& [key, p] : best) points_m_.push_back(p);
  // Hash order is not portable: sort so the tree (and the leaf ids) are.
  std::sort(points_m_.begin(), points_m_.end(),
            [](const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
              return std::tie(p.x(), p.y(), p.z()) < std::tie(q.x(), q.y(), q.z());
            });
  nodes_.reserve(2 * (points_m_.size() / static_cast<std::size_t>(settings.leaf_size) + 1));
  nodes_.emplace_back();
  build(0, 0, static_cast<std::int32_t>(points_m_.size()), 1, settings.leaf_size);
}

void SurfaceSamples::build(std::int32_t node, std::int32_t begin, std::int32_t end, int depth,
                           int leaf_size) {
  depth_ = std::max(depth_, depth);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (std::int32_t i = begin; i < end; ++i) {
    lo = lo.cwiseMin(points_m_[i]);
    hi = hi.cwiseMax(points_m_[i]);
  }
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  double radius = 0.0;
  for (std::int32_t i = begin; i < end; ++i)
    radius = std::max(radius, (points_m_[i] - centre).norm());
  nodes_[node].centre_m = centre;
  nodes_[node].radius_m = radius;
  if (end - begin <= leaf_size || depth >= kMaxDepth - 1) {
    nodes_[node].first = begin;
    nodes_[node].count = end - begin;
    return;
  }
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  const std::int32_t mid = begin + (end - begin) / 2;
  std::nth_element(points_m_.begin() + begin, points_m_.begin() + mid, points_m_.begin() + end,
                   [axis](const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
                     return std::tie(p[axis], p.x(), p.y(), p.z()) <
                            std::tie(q[axis], q.x(), q.y(), q.z());
                   });
  const auto left = static_cast<std::int32_t>(nodes_.size());
  nodes_.emplace_back();
  nodes_.emplace_back();
  nodes_[node].first = left;
  nodes_[node].count = 0;
  build(left, begin, mid, depth + 1, leaf_size);
  build(left + 1, mid, end, depth + 1, leaf_size);
}

SurfaceQueryStats query_surface_samples(const SurfaceSamples& samples,
                                        const Eigen::Isometry3d& world_from_tool,
                                        const RigidBody& body, double margin_m,
                                        std::span<SurfaceContact> out,
                                        std::size_t& count) noexcept {
  SurfaceQueryStats stats;
  const auto& nodes = samples.nodes();
  if (nodes.empty() || body.sdf == nullptr) return stats;
  const geometry::SignedDistanceField& sdf = *body.sdf;
  const Eigen::Isometry3d body_from_tool = body.world_from_body.inverse() * world_from_tool;
  const double grid_error = kGridErrorCells * sdf.cell_size_m();
  const auto& points = samples.points_m();

  std::int32_t stack[SurfaceSamples::kMaxDepth + 1];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const std::int32_t index = stack[--top];
    const SurfaceSampleNode& node = nodes[index];
    ++stats.nodes_visited;
    const double d = sdf.grid_distance(body_from_tool * node.centre_m);
    if (!(d - grid_error <= node.radius_m + margin_m)) continue;  // also drops a NaN pose
    if (node.count == 0) {
      stack[top++] = node.first;
      stack[top++] = node.first + 1;
      continue;
    }
    // Leaf: each of its samples within the margin.
    for (std::int32_t i = node.first; i < node.first + node.count; ++i) {
      const Eigen::Vector3d p = body_from_tool * points[i];
      const double di = sdf.grid_distance(p);
      ++stats.points_tested;
      if (!(di < margin_m)) continue;
      // The field's gradient by central differences of half a cell.
      const double step = 0.5 * sdf.cell_size_m();
      Eigen::Vector3d gradient;
      for (int axis = 0; axis < 3; ++axis) {
        const Eigen::Vector3d e = step * Eigen::Vector3d::Unit(axis);
        gradient[axis] = sdf.grid_distance(p + e) - sdf.grid_distance(p - e);
      }
      const double norm = gradient.norm();
      if (!(norm > 0.0)) continue;  // a flat spot of the field (deep inside): no direction to push
      const Eigen::Vector3d n_body = gradient / norm;
      ++stats.contacts;
      if (count >= out.size()) {
        stats.overflowed = true;
        continue;
      }
      SurfaceContact& c = out[count++];
      c.sample = static_cast<std::uint32_t>(i);
      c.body_id = body.id;
      c.tool_point_m = world_from_tool * points[i];
      c.surface_point_m = body.world_from_body * Eigen::Vector3d(p - di * n_body);
      c.normal = body.world_from_body.linear() * n_body;
      c.depth_m = -di;
    }
  }
  return stats;
}

}  // namespace fahr::collision
