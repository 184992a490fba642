// What the FEM needs to know of a static rigid obstacle (jaw, palate) to
// keep its nodes out of it: a signed distance and the direction out. An
// interface, so fahr::fem stays free of libs/geometry: the FEM service
// adapts the scene's signed distance fields (fem_service/anatomy_fields.h),
// tests use analytic shapes.
#pragma once

#include <Eigen/Core>

namespace fahr::fem {

struct ObstacleSample {
  // Signed distance from the obstacle's surface, m: > 0 outside, < 0 inside,
  // NaN when the point cannot be answered (a non-finite point). Near the
  // surface (within a millimetre or so) it must be accurate; farther outside
  // it may be underestimated but never overestimated, because the projection
  // uses it as a clearance: a node that has moved less than that since it was
  // sampled is not sampled again.
  double distance_m = 0.0;
  // Unit normal pointing out of the obstacle (the direction that increases
  // the distance), in the FEM's frame. Only read when distance_m is small.
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
};

class ObstacleField {
 public:
  virtual ~ObstacleField() = default;
  // p_m in the FEM body's frame, m. Must not allocate: called in the step.
  virtual ObstacleSample sample(const Eigen::Vector3d& p_m) const noexcept = 0;
};

}  // namespace fahr::fem
