// Wire <-> library conversions of the FEM service.
#include "fahr/fem_service/contact_conversion.h"

#include <algorithm>
#include <cmath>

#include "fahr/common/wire_eigen.h"

namespace fahr::fem_service {

using common::to_eigen;

void to_fem(const msg::ContactSet& wire, fem::ContactSet& out) {
  out.state_step = wire.fem_step();
  out.contacts.resize(wire.contacts().size());
  for (std::size_t i = 0; i < wire.contacts().size(); ++i) {
    const auto& w = wire.contacts()[i];
    auto& c = out.contacts[i];
    c.sphere_id = w.sphere_id();
    c.kind = w.kind() == msg::CONTACT_OBSTACLE     ? fem::ContactKind::kObstacle
             : w.kind() == msg::CONTACT_FORCE_ONLY ? fem::ContactKind::kForceOnly
                                                   : fem::ContactKind::kTool;
    c.state = w.state() == msg::CONSTRAINT_ACTIVE   ? fem::ContactState::kActive
              : w.state() == msg::CONSTRAINT_FROZEN ? fem::ContactState::kFrozen
                                                    : fem::ContactState::kCandidate;
    c.plane_point_m = to_eigen(w.point_m());
    c.normal = to_eigen(w.normal());
    c.hold_centre_m = to_eigen(w.hold_centre_m());
    c.penetration_m = w.penetration_m();
    c.force_n = w.force_n();
  }
}

bool all_finite(const msg::ContactSet& wire) {
  for (const auto& w : wire.contacts()) {
    if (!to_eigen(w.point_m()).allFinite() || !to_eigen(w.normal()).allFinite() ||
        !to_eigen(w.hold_centre_m()).allFinite() || !std::isfinite(w.penetration_m()) ||
        !std::isfinite(w.force_n())) {
      return false;
    }
  }
  const auto& pose = wire.world_from_tool();
  const auto& q = pose.orientation();
  return to_eigen(pose.position_m()).allFinite() && std::isfinite(q.w()) && std::isfinite(q.x()) &&
         std::isfinite(q.y()) && std::isfinite(q.z());
}

void fill_state(const fem::Body& body, std::uint32_t body_id, msg::DeformationState& out) {
  out.body_id(body_id);
  out.step(body.step_index());
  out.step_s(body.time_step_s());
  out.asleep(body.asleep());
  out.stale_contact_sets(static_cast<std::uint32_t>(body.stale_sets_ignored()));
  const auto x = body.positions_m();
  const auto v = body.velocities_m_per_s();
  out.positions_m().resize(x.size());
  out.velocities_mps().resize(v.size());
  for (std::size_t i = 0; i < x.size(); ++i) out.positions_m()[i] = static_cast<float>(x[i]);
  for (std::size_t i = 0; i < v.size(); ++i) out.velocities_mps()[i] = static_cast<float>(v[i]);
}

}  // namespace fahr::fem_service
