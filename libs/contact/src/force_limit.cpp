// Saturation of the commanded force and its local stiffness.
#include "fahr/contact/force_limit.h"

#include <algorithm>

namespace fahr::contact {

bool limit_force(double limit_n, Eigen::Vector3d& force_n, Eigen::Matrix3d& stiffness_npm) {
  const double limit = std::max(limit_n, 0.0);
  const double magnitude = force_n.norm();
  if (!(magnitude > limit)) return false;
  const double scale = limit / magnitude;
  const Eigen::Vector3d u = force_n / magnitude;
  const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - u * u.transpose();
  force_n *= scale;
  const Eigen::Matrix3d k = scale * (across * stiffness_npm * across);
  stiffness_npm = 0.5 * (k + k.transpose());
  return true;
}

}  // namespace fahr::contact
