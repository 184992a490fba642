// A sphere of the filling before it is tied to tets (internal).
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "fahr/sphere_layout/sphere_layout.h"

namespace fahr::sphere_layout::detail {

struct CandidateSphere {
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();  // m
  double radius_m = 0.0;                               // m
  std::uint8_t level = 0;
  SphereOrigin origin = SphereOrigin::kGrid;
};

}  // namespace fahr::sphere_layout::detail
