// Point-triangle closest point (Ericson, Real-Time Collision Detection, 5.1.5),
// with the feature it lands on.
#include "fahr/geometry/closest_point.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <limits>

namespace fahr::geometry {
namespace {

// A triangle whose sin^2 of the corner angle at a is below one epsilon has no
// usable plane: the face-region barycentrics would divide by ~0. Its closest
// point then lies on one of its edges.
constexpr double kDegenerateSinSquared = std::numeric_limits<double>::epsilon();

struct SegmentPoint {
  Eigen::Vector3d point;
  double t;  // 0 at the first end, 1 at the second
};

SegmentPoint closest_on_segment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length_squared = ab.squaredNorm();
  const double t =
      length_squared > 0.0 ? std::clamp((p - a).dot(ab) / length_squared, 0.0, 1.0) : 0.0;
  return {a + t * ab, t};
}

TriangleFeature segment_feature(double t, TriangleFeature start, TriangleFeature end,
                                TriangleFeature edge) {
  if (t <= 0.0) {
    return start;
  }
  return t >= 1.0 ? end : edge;
}

TriangleClosestPoint degenerate_closest(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                        const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const SegmentPoint s01 = closest_on_segment(p, a, b);
  const SegmentPoint s12 = closest_on_segment(p, b, c);
  const SegmentPoint s20 = closest_on_segment(p, c, a);
  TriangleClosestPoint best{s01.point, (p - s01.point).squaredNorm(),
                            segment_feature(s01.t, TriangleFeature::kVertex0,
                                            TriangleFeature::kVertex1, TriangleFeature::kEdge01)};
  const double d12 = (p - s12.point).squaredNorm();
  if (d12 < best.distance_squared) {
    best = {s12.point, d12,
            segment_feature(s12.t, TriangleFeature::kVertex1, TriangleFeature::kVertex2,
                            TriangleFeature::kEdge12)};
  }
  const double d20 = (p - s20.point).squaredNorm();
  if (d20 < best.distance_squared) {
    best = {s20.point, d20,
            segment_feature(s20.t, TriangleFeature::kVertex2, TriangleFeature::kVertex0,
                            TriangleFeature::kEdge20)};
  }
  return best;
}

TriangleClosestPoint make(const Eigen::Vector3d& p, const Eigen::Vector3d& point,
                          TriangleFeature feature) {
  return {point, (p - point).squaredNorm(), feature};
}

}  // namespace

TriangleClosestPoint closest_point_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                               const Eigen::Vector3d& b,
                                               const Eigen::Vector3d& c) noexcept {
  const Eigen::Vector3d ab = b - a;
  const Eigen::Vector3d ac = c - a;
  const double cross_squared = ab.cross(ac).squaredNorm();
  if (cross_squared <= kDegenerateSinSquared * ab.squaredNorm() * ac.squaredNorm()) {
    return degenerate_closest(p, a, b, c);
  }
  // Vertex region of a.
  const Eigen::Vector3d ap = p - a;
  const double d1 = ab.dot(ap);
  const double d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) {
    return make(p, a, TriangleFeature::kVertex0);
  }
  // Vertex region of b.
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp);
  const double d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) {
    return make(p, b, TriangleFeature::kVertex1);
  }
  // Edge region of ab.
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    return make(p, a + (d1 / (d1 - d3)) * ab, TriangleFeature::kEdge01);
  }
  // Vertex region of c.
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp);
  const double d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) {
    return make(p, c, TriangleFeature::kVertex2);
  }
  // Edge region of ca.
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    return make(p, a + (d2 / (d2 - d6)) * ac, TriangleFeature::kEdge20);
  }
  // Edge region of bc.
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return make(p, b + w * (c - b), TriangleFeature::kEdge12);
  }
  // Face region: barycentrics from the sub-areas.
  const double denominator = 1.0 / (va + vb + vc);
  const double v = vb * denominator;
  const double w = vc * denominator;
  return make(p, a + v * ab + w * ac, TriangleFeature::kFace);
}

}  // namespace fahr::geometry
