// TriangleBvh: median-split AABB tree and its allocation-free closest-point walk.
#include "fahr/geometry/triangle_bvh.h"

#include <algorithm>
#include <array>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace fahr::geometry {
namespace {

double box_distance_squared(const Eigen::Vector3d& p, const Eigen::Vector3d& lo,
                            const Eigen::Vector3d& hi) {
  const Eigen::Vector3d below = (lo - p).cwiseMax(0.0);
  const Eigen::Vector3d above = (p - hi).cwiseMax(0.0);
  return (below + above).squaredNorm();
}

}  // namespace

TriangleBvh::TriangleBvh(const SurfaceMesh& mesh) {
  const std::size_t count = mesh.triangle_count();
  if (count == 0) {
    return;
  }
  const auto& vertices = mesh.vertices();
  const auto& triangles = mesh.triangles();
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

}  // namespace fahr::geometry
