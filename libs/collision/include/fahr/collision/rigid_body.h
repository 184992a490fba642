// A rigid body the spheres collide with: its signed distance field (in its
// own frame) and its pose. The field is borrowed: it must outlive the body.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>

#include "fahr/collision/field_grid.h"
#include "fahr/geometry/signed_distance_field.h"

namespace fahr::collision {

struct RigidBody {
  std::uint32_t id = 0;  // reported in contacts
  const geometry::SignedDistanceField* sdf = nullptr;
  // Pose: world_from_body maps body-frame points (m) to the world frame.
  Eigen::Isometry3d world_from_body = Eigen::Isometry3d::Identity();
  // Optional, borrowed like the field: a FieldGrid of that field. With it the
  // queries read the grid there (the grid narrow phase one cell per sphere
  // instead of seven, docs/design/aist-layout.md); without it, the field's own.
  const FieldGrid* grid = nullptr;
};

}  // namespace fahr::collision
