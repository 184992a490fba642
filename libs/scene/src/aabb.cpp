#include "fahr/scene/aabb.h"

namespace fahr::scene {

bool Aabb::contains(const Eigen::Vector3d& point_m) const {
  return (point_m.array() >= min_m.array()).all() && (point_m.array() <= max_m.array()).all();
}

Aabb Aabb::inflated(double margin_m) const {
  const Eigen::Vector3d grow = Eigen::Vector3d::Constant(margin_m);
  return Aabb{min_m - grow, max_m + grow};
}

bool Aabb::overlaps(const Aabb& other) const {
  return (min_m.array() <= other.max_m.array()).all() &&
         (other.min_m.array() <= max_m.array()).all();
}

}  // namespace fahr::scene
