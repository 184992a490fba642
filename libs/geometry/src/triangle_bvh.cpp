// TriangleBvh: median-split AABB tree and its allocation-free closest-point walk.
#include "fahr/geometry/triangle_bvh.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace fahr::geometry {
namespace {

double box_distance_squared(const Eigen::Vector3d& p, const Eigen::Vector3d& lo,
                            const Eigen::Vector3d& hi) {
  const Eigen::Vector3d below = (lo - p).cwiseMax(0.0);
  const Eigen::Vector3d above = (p - hi).cwiseMax(0.0);
  return (below + above).squaredNorm();
}

// The segment a + t (b - a), t in [0, 1], against a box (slab test).
bool segment_meets_box(const Eigen::Vector3d& a, const Eigen::Vector3d& inverse_d,
                       const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  double t0 = 0.0;
  double t1 = 1.0;
  for (int k = 0; k < 3; ++k) {
    // inverse_d is +-inf on an axis the segment does not move along: the
    // products are then +-inf (outside the slab) or NaN (on its face), and
    // NaN comparisons leave t0 and t1 as they are.
    double near = (lo[k] - a[k]) * inverse_d[k];
    double far = (hi[k] - a[k]) * inverse_d[k];
    if (near > far) std::swap(near, far);
    if (near > t0) t0 = near;
    if (far < t1) t1 = far;
    if (t0 > t1) return false;
  }
  return true;
}

// Moller-Trumbore: the segment a + t d crosses the triangle at t in
// (kEnd, 1 - kEnd). Triangles seen edge-on (|det| tiny against the sizes
// involved) do not block.
constexpr double kSegmentEnd = 1e-9;

bool segment_crosses_triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& d,
                              const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                              const Eigen::Vector3d& p2) {
  const Eigen::Vector3d e1 = p1 - p0;
  const Eigen::Vector3d e2 = p2 - p0;
  const Eigen::Vector3d h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) <= 1e-14 * e1.norm() * e2.norm() * d.norm()) return false;
  const double inv = 1.0 / det;
  const Eigen::Vector3d s = a - p0;
  const double u = inv * s.dot(h);
  if (u < 0.0 || u > 1.0) return false;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = inv * d.dot(q);
  if (v < 0.0 || u + v > 1.0) return false;
  const double t = inv * e2.dot(q);
  return t > kSegmentEnd && t < 1.0 - kSegmentEnd;
}

}  // namespace

TriangleBvh::TriangleBvh(const SurfaceMesh& mesh)
    : TriangleBvh(std::span<const Eigen::Vector3d>(mesh.vertices()),
                  std::span<const Triangle>(mesh.triangles())) {}

TriangleBvh::TriangleBvh(std::span<const Eigen::Vector3d> vertices,
                         std::span<const Triangle> triangles) {
  const std::size_t count = triangles.size();
  if (count == 0) {
    return;
  }
  for (const Triangle& t : triangles) {
    for (const Index i : t) {
      if (i < 0 || static_cast<std::size_t>(i) >= vertices.size()) {
        throw std::out_of_range("triangle BVH: vertex index " + std::to_string(i) + " of " +
                                std::to_string(vertices.size()) + " vertices");
      }
    }
  }
  order_.resize(count);
  std::iota(order_.begin(), order_.end(), Index{0});
  std::vector<Eigen::Vector3d> centroids(count);
  for (std::size_t t = 0; t < count; ++t) {
    centroids[t] =
        (vertices[triangles[t][0]] + vertices[triangles[t][1]] + vertices[triangles[t][2]]) / 3.0;
  }
  corners_.resize(count);
  for (std::size_t t = 0; t < count; ++t) {
    corners_[t] = {vertices[triangles[t][0]], vertices[triangles[t][1]], vertices[triangles[t][2]]};
  }
  nodes_.reserve(2 * count / static_cast<std::size_t>(kLeafSize) + 2);
  nodes_.push_back({});
  build(0, 0, static_cast<std::int32_t>(count), 1, centroids);
  if (depth_ > kMaxDepth) {
    // Unreachable with median splits below 2^40 triangles; the query stack relies on it.
    throw std::length_error("triangle BVH deeper than kMaxDepth");
  }
  // corners_ was filled in triangle order; put it in leaf order for the walk.
  std::vector<TriangleCorners> ordered(count);
  for (std::size_t i = 0; i < count; ++i) {
    ordered[i] = corners_[order_[i]];
  }
  corners_ = std::move(ordered);
}

void TriangleBvh::build(std::int32_t index, std::int32_t begin, std::int32_t end, int depth,
                        const std::vector<Eigen::Vector3d>& centroids) {
  depth_ = std::max(depth_, depth);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  Eigen::Vector3d centroid_lo = lo;
  Eigen::Vector3d centroid_hi = hi;
  for (std::int32_t i = begin; i < end; ++i) {
    const TriangleCorners& t = corners_[order_[i]];
    lo = lo.cwiseMin(t.a).cwiseMin(t.b).cwiseMin(t.c);
    hi = hi.cwiseMax(t.a).cwiseMax(t.b).cwiseMax(t.c);
    centroid_lo = centroid_lo.cwiseMin(centroids[order_[i]]);
    centroid_hi = centroid_hi.cwiseMax(centroids[order_[i]]);
  }
  nodes_[index].box_min = lo;
  nodes_[index].box_max = hi;
  if (end - begin <= kLeafSize) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return;
  }
  int axis = 0;
  (centroid_hi - centroid_lo).maxCoeff(&axis);
  const std::int32_t middle = begin + (end - begin) / 2;
  std::nth_element(order_.begin() + begin, order_.begin() + middle, order_.begin() + end,
                   [&](Index l, Index r) { return centroids[l][axis] < centroids[r][axis]; });
  // Siblings sit next to each other, so an inner node stores only its left child.
  const auto left = static_cast<std::int32_t>(nodes_.size());
  nodes_[index].first = left;
  nodes_[index].count = 0;
  nodes_.push_back({});
  nodes_.push_back({});
  build(left, begin, middle, depth + 1, centroids);
  build(left + 1, middle, end, depth + 1, centroids);
}

void TriangleBvh::leaf_test(const Node& node, const Eigen::Vector3d& p,
                            BvhClosestPoint& best) const noexcept {
  for (std::int32_t i = node.first; i < node.first + node.count; ++i) {
    const TriangleCorners& t = corners_[static_cast<std::size_t>(i)];
    const TriangleClosestPoint hit = closest_point_on_triangle(p, t.a, t.b, t.c);
    if (hit.distance_squared < best.distance_squared) {
      best.point = hit.point;
      best.distance_squared = hit.distance_squared;
      best.feature = hit.feature;
      best.triangle = order_[static_cast<std::size_t>(i)];
    }
  }
}

BvhClosestPoint TriangleBvh::closest_point(const Eigen::Vector3d& p,
                                           double bound_squared) const noexcept {
  BvhClosestPoint best;
  best.distance_squared = bound_squared;
  if (nodes_.empty()) {
    return best;
  }
  std::array<std::int32_t, kMaxDepth + 2> stack{};
  int top = 0;
  stack[static_cast<std::size_t>(top++)] = 0;
  while (top > 0) {
    const Node& node = nodes_[static_cast<std::size_t>(stack[static_cast<std::size_t>(--top)])];
    if (box_distance_squared(p, node.box_min, node.box_max) >= best.distance_squared) {
      continue;
    }
    if (node.count > 0) {
      leaf_test(node, p, best);
      continue;
    }
    // Visit the nearer child first (pushed last) so the bound shrinks early.
    const std::int32_t left = node.first;
    const std::int32_t right = left + 1;
    const double dl = box_distance_squared(p, nodes_[static_cast<std::size_t>(left)].box_min,
                                           nodes_[static_cast<std::size_t>(left)].box_max);
    const double dr = box_distance_squared(p, nodes_[static_cast<std::size_t>(right)].box_min,
                                           nodes_[static_cast<std::size_t>(right)].box_max);
    const bool left_first = dl <= dr;
    stack[static_cast<std::size_t>(top++)] = left_first ? right : left;
    stack[static_cast<std::size_t>(top++)] = left_first ? left : right;
  }
  return best;
}

BvhClosestPoint TriangleBvh::closest_point_brute_force(const Eigen::Vector3d& p) const noexcept {
  BvhClosestPoint best;
  best.distance_squared = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < corners_.size(); ++i) {
    const TriangleCorners& t = corners_[i];
    const TriangleClosestPoint hit = closest_point_on_triangle(p, t.a, t.b, t.c);
    if (hit.distance_squared < best.distance_squared) {
      best = {hit.point, hit.distance_squared, order_[i], hit.feature};
    }
  }
  return best;
}

bool TriangleBvh::segment_hits(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const noexcept {
  if (nodes_.empty()) {
    return false;
  }
  const Eigen::Vector3d d = b - a;
  const Eigen::Vector3d inverse_d = d.cwiseInverse();
  std::array<std::int32_t, kMaxDepth + 2> stack{};
  int top = 0;
  stack[static_cast<std::size_t>(top++)] = 0;
  while (top > 0) {
    const Node& node = nodes_[static_cast<std::size_t>(stack[static_cast<std::size_t>(--top)])];
    if (!segment_meets_box(a, inverse_d, node.box_min, node.box_max)) {
      continue;
    }
    if (node.count > 0) {
      for (std::int32_t i = node.first; i < node.first + node.count; ++i) {
        const TriangleCorners& t = corners_[static_cast<std::size_t>(i)];
        if (segment_crosses_triangle(a, d, t.a, t.b, t.c)) return true;
      }
      continue;
    }
    stack[static_cast<std::size_t>(top++)] = node.first;
    stack[static_cast<std::size_t>(top++)] = node.first + 1;
  }
  return false;
}

bool TriangleBvh::segment_hits_brute_force(const Eigen::Vector3d& a,
                                           const Eigen::Vector3d& b) const noexcept {
  const Eigen::Vector3d d = b - a;
  for (const TriangleCorners& t : corners_) {
    if (segment_crosses_triangle(a, d, t.a, t.b, t.c)) return true;
  }
  return false;
}

}  // namespace fahr::geometry
