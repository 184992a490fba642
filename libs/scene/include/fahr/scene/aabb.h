// Axis-aligned box in the world frame, metres. Used for fixed-node regions and
// for the body bounds the run plan filters contact pairs with.
#pragma once

#include <Eigen/Core>

namespace fahr::scene {

struct Aabb {
  Eigen::Vector3d min_m = Eigen::Vector3d::Zero();  // world frame, m
  Eigen::Vector3d max_m = Eigen::Vector3d::Zero();  // world frame, m; >= min_m

  bool contains(const Eigen::Vector3d& point_m) const;
  // The box grown by margin_m (>= 0) on every side.
  Aabb inflated(double margin_m) const;
  // True when the two boxes share a point (touching faces count).
  bool overlaps(const Aabb& other) const;
};

}  // namespace fahr::scene
