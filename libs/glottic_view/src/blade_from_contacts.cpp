// The blade's pose and force on the tissue from a ContactSet.
#include "fahr/glottic_view/blade_from_contacts.h"

#include <cmath>

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
  Eigen::Vector3d force = Eigen::Vector3d::Zero();
  for (const auto& c : set.contacts()) {
    if (c.kind() == msg::CONTACT_OBSTACLE) continue;
    force += c.force_n() * Eigen::Vector3d(c.normal().x(), c.normal().y(), c.normal().z());
  }
  out.tool_force_n = force.allFinite() ? force.norm() : 0.0;
  return out;
}

}  // namespace fahr::glottic_view
