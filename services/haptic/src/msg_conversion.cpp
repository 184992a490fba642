// Wire conversions of the haptic service.
#include "fahr/haptic_service/msg_conversion.h"

#include <algorithm>

#include "fahr/common/wire_eigen.h"

namespace fahr::haptic_service {

using common::put;

void fill_command(const contact::ForceOutput& output, std::uint32_t device_id,
                  msg::ForceCommand& out) {
  out.device_id(device_id);
  out.answered_pose_seq(output.answered_pose_seq);
  put(output.answered_position_m, out.answered_position_m());
  put(output.force_n, out.force_n());
  put(output.stiffness_npm, out.stiffness_npm());
  put(Eigen::Vector3d::Zero(), out.torque_nm());  // the rigid blade's torque is not computed yet
  put(output.proxy_position_m, out.world_from_proxy().position_m());
  put(output.proxy_orientation, out.world_from_proxy().orientation());
  out.lost_track(output.lost_track);
  put(output.device_minus_proxy_m, out.device_minus_proxy_m());
  out.tissue_reaction_n(output.tissue_reaction_n);
  out.active_contacts(output.active_contacts);
  out.fem_step(output.fem_step);
}

namespace {

msg::ConstraintState wire_state(fem::ContactState s) {
  switch (s) {
    case fem::ContactState::kActive:
      return msg::CONSTRAINT_ACTIVE;
    case fem::ContactState::kFrozen:
      return msg::CONSTRAINT_FROZEN;
    case fem::ContactState::kCandidate:
      break;
  }
  return msg::CONSTRAINT_CANDIDATE;
}

}  // namespace

void fill_contacts(std::span<const fem::Contact> contacts, std::span<const fem::Contact> requests,
                   std::uint32_t tool_body_id, std::span<const std::uint32_t> obstacle_body_ids,
                   msg::ContactSet& out) {
  const std::size_t n = std::min<std::size_t>(contacts.size() + requests.size(), msg::MAX_CONTACTS);
  out.contacts().resize(n);
  std::size_t obstacle = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const fem::Contact& c = i < contacts.size() ? contacts[i] : requests[i - contacts.size()];
    msg::Contact& w = out.contacts()[i];
    w.sphere_id(c.sphere_id);
    if (c.kind == fem::ContactKind::kObstacle) {
      w.kind(msg::CONTACT_OBSTACLE);
      w.other_body_id(obstacle < obstacle_body_ids.size() ? obstacle_body_ids[obstacle] : 0u);
      ++obstacle;
    } else {
      w.kind(c.kind == fem::ContactKind::kForceOnly ? msg::CONTACT_FORCE_ONLY : msg::CONTACT_TOOL);
      w.other_body_id(tool_body_id);
    }
    w.state(wire_state(c.state));
    put(c.plane_point_m, w.point_m());
    put(c.normal, w.normal());
    put(c.hold_centre_m, w.hold_centre_m());
    w.penetration_m(c.penetration_m);
    w.force_n(c.force_n);
  }
}

}  // namespace fahr::haptic_service
