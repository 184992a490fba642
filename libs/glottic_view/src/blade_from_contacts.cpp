// The blade's pose and force on the tissue from a ContactSet.
#include "fahr/glottic_view/blade_from_contacts.h"

#include <cmath>

#include "fahr/common/tool_row_forces.h"

namespace fahr::glottic_view {

BladeFromContacts blade_from_contacts(const msg::ContactSet& set) {
  BladeFromContacts out;
  const auto& p = set.world_from_tool();
  const auto& q = p.orientation();
  const double length = std::sqrt(q.w() * q.w() + q.x() * q.x() + q.y() * q.y() + q.z() * q.z());
  const Eigen::Vector3d position(p.position_m().x(), p.position_m().y(), p.position_m().z());
  if (length > 0.5 && std::isfinite(length) && position.allFinite()) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = Eigen::Quaterniond(q.w(), q.x(), q.y(), q.z()).normalized().toRotationMatrix();
    pose.translation() = position;
    out.world_from_tool = pose;
  }
  const Eigen::Vector3d force = common::tool_row_forces(set).resultant_n;
  out.tool_force_n = force.allFinite() ? force.norm() : 0.0;
  return out;
}

}  // namespace fahr::glottic_view
