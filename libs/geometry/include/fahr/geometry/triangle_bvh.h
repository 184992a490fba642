// Axis-aligned bounding-box tree over the triangles of a surface for exact
// closest-point and segment-occlusion queries. Built once; queries walk a
// fixed-size stack and never allocate, so they can run in a 1 kHz loop.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "fahr/geometry/closest_point.h"
#include "fahr/geometry/surface_mesh.h"

namespace fahr::geometry {

struct BvhClosestPoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // m
  double distance_squared = 0.0;                    // m^2
  Index triangle = -1;                              // -1 when nothing lies within the bound
  TriangleFeature feature = TriangleFeature::kFace;
};

class TriangleBvh {
 public:
  // Median splits keep the tree balanced, so its depth is at most
  // log2(triangles) + 1 and this stack holds any tree of up to 2^40 triangles.
  static constexpr int kMaxDepth = 48;
  static constexpr int kLeafSize = 4;  // triangles per leaf: fewer box tests, few triangle tests

  TriangleBvh() = default;
  explicit TriangleBvh(const SurfaceMesh& mesh);
  // The same over triangles of `vertices` (m) that need not form a checked
  // surface, e.g. a deformed body's boundary. Throws std::out_of_range on an
  // index outside `vertices`.
  TriangleBvh(std::span<const Eigen::Vector3d> vertices, std::span<const Triangle> triangles);

  // The closest surface point to p among points closer than sqrt(bound_squared)
  // (m^2; infinity to search everything). triangle == -1 when none is.
  BvhClosestPoint closest_point(const Eigen::Vector3d& p, double bound_squared) const noexcept;

  // The same by testing every triangle: the reference for tests and benchmarks.
  BvhClosestPoint closest_point_brute_force(const Eigen::Vector3d& p) const noexcept;

  // Whether any triangle crosses the segment from a to b (m), ends excluded
  // (a crossing within 1e-9 of the segment's length from either end does not
  // count): a line of sight between two points is blocked.
  bool segment_hits(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const noexcept;

  // The same by testing every triangle: the reference for tests.
  bool segment_hits_brute_force(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const noexcept;

  int depth() const { return depth_; }

 private:
  struct Node {
    Eigen::Vector3d box_min = Eigen::Vector3d::Zero();  // m
    Eigen::Vector3d box_max = Eigen::Vector3d::Zero();  // m
    std::int32_t first = 0;  // leaf: first triangle in order_; inner: left child (right = left + 1)
    std::int32_t count = 0;  // leaf: triangle count; inner: 0
  };
  struct TriangleCorners {
    Eigen::Vector3d a = Eigen::Vector3d::Zero();  // m
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
  };

  void build(std::int32_t index, std::int32_t begin, std::int32_t end, int depth,
             const std::vector<Eigen::Vector3d>& centroids);
  void leaf_test(const Node& node, const Eigen::Vector3d& p, BvhClosestPoint& best) const noexcept;

  std::vector<Node> nodes_;
  std::vector<Index> order_;              // triangle ids in leaf order
  std::vector<TriangleCorners> corners_;  // corners in leaf order, for cache-friendly tests
  int depth_ = 0;
};

}  // namespace fahr::geometry
