// Exact closest point on a triangle, with the feature (vertex, edge, face)
// it lies on: the sign of a distance needs the pseudo-normal of that feature.
#pragma once

#include <Eigen/Core>

namespace fahr::geometry {

enum class TriangleFeature : unsigned char {
  kVertex0,
  kVertex1,
  kVertex2,
  kEdge01,
  kEdge12,
  kEdge20,
  kFace,
};

struct TriangleClosestPoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  // m
  double distance_squared = 0.0;                    // m^2
  TriangleFeature feature = TriangleFeature::kFace;
};

// Voronoi-region walk of Ericson, Real-Time Collision Detection (2005), 5.1.5.
// Degenerate (zero-area) triangles fall back to their edges and stay exact.
TriangleClosestPoint closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                               const Eigen::Vector3d& b,
                                               const Eigen::Vector3d& c) noexcept;

}  // namespace fahr::geometry
