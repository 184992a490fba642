// The scene's rigid anatomy as the FEM body sees it: each obstacle the body
// is held out of (the scene plan's hard pairs) as a fem::ObstacleField over
// the same signed distance field the haptic service builds (libs/runtime),
// so the FEM keeps its own nodes out of bone in every step.
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <vector>

#include "fahr/fem/obstacle_field.h"
#include "fahr/runtime/rigid_field.h"
#include "fahr/scene/scene.h"

namespace fahr::fem_service {

class AnatomyField final : public fem::ObstacleField {
 public:
  explicit AnatomyField(std::unique_ptr<runtime::RigidField> field);

  // p_m in the world frame (the FEM body's frame). Exact within the field's
  // band around the surface; beyond it, outside, the grid's value less its
  // error bound (a distance never overestimated, as ObstacleField asks).
  fem::ObstacleSample sample(const Eigen::Vector3d& p_m) const noexcept override;

  const runtime::RigidField& field() const { return *field_; }

 private:
  std::unique_ptr<runtime::RigidField> field_;
  Eigen::Isometry3d body_from_world_;
  Eigen::Matrix3d world_from_body_rotation_;
  double far_error_m_;  // the grid's error beyond the exact band, m
};

// Throws std::runtime_error naming the body whose field cannot be built.
std::vector<std::unique_ptr<AnatomyField>> load_anatomy_fields(const scene::Scene& scene,
                                                               const scene::Body& deformable);

}  // namespace fahr::fem_service
