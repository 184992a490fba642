// Scene anatomy -> fem::ObstacleFields (see anatomy_fields.h).
#include "fahr/fem_service/anatomy_fields.h"

#include <cmath>
#include <limits>

namespace fahr::fem_service {
namespace {

// geometry::SdfOptions: "Far-field error is at most sqrt(3) cells."
constexpr double kCellDiagonal = 1.7320508075688772;

}  // namespace

AnatomyField::AnatomyField(std::unique_ptr<runtime::RigidField> field)
    : field_(std::move(field)),
      body_from_world_(field_->world_from_body().inverse()),
      world_from_body_rotation_(field_->world_from_body().linear()),
      far_error_m_(kCellDiagonal * field_->sdf->cell_size_m()) {}

fem::ObstacleSample AnatomyField::sample(const Eigen::Vector3d& p_m) const noexcept {
  fem::ObstacleSample out;
  if (!p_m.allFinite()) {
    out.distance_m = std::numeric_limits<double>::quiet_NaN();
    return out;
  }
  const geometry::SdfSample s = field_->sdf->query(body_from_world_ * p_m);
  const bool far_outside = !s.exact && s.distance_m > 0.0;
  out.distance_m = far_outside ? s.distance_m - far_error_m_ : s.distance_m;
  out.normal = world_from_body_rotation_ * s.normal;
  return out;
}

std::vector<std::unique_ptr<AnatomyField>> load_anatomy_fields(const scene::Scene& scene,
                                                               const scene::Body& deformable) {
  const auto index = static_cast<std::size_t>(&deformable - scene.bodies.data());
  std::vector<std::unique_ptr<AnatomyField>> fields;
  for (const std::size_t obstacle : runtime::hard_obstacles_of(scene, index)) {
    fields.push_back(
        std::make_unique<AnatomyField>(runtime::load_rigid_field(scene.bodies[obstacle])));
  }
  return fields;
}

}  // namespace fahr::fem_service
