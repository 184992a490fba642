// The AIST's touching spheres as the FEM's tool contacts, for the benches'
// closed loop (Algorithm 1 projects each out of the blade): `trajectory`
// steps the FEM on them and `record` saves the states that gives.
#pragma once

#include <cstdint>

#include "fahr/collision/contact_buffer.h"
#include "fahr/fem/contact_set.h"

namespace fahr::aist_bench {

inline void fill_sphere_contacts(const collision::ContactBuffer& buffer, std::uint64_t state_step,
                                 fem::ContactSet& set) {
  set.state_step = state_step;
  set.contacts.clear();
  for (const collision::SphereContact& c : buffer) {
    if (c.candidate) continue;  // near, not touching: nothing to project
    fem::Contact contact;
    contact.sphere_id = c.sphere_id;
    contact.kind = fem::ContactKind::kTool;
    contact.state = fem::ContactState::kActive;
    contact.plane_point_m = c.point_m;
    contact.normal = c.normal;
    contact.penetration_m = c.depth_m;
    set.contacts.push_back(contact);
  }
}

}  // namespace fahr::aist_bench
