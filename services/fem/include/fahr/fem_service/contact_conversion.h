// The wire ContactSet (idl) to the FEM library's ContactSet, and the FEM
// state to the wire DeformationState. Conversion into preallocated
// containers: nothing allocates once they have reached their largest size.
#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "contact_set.h"
#include "deformation_state.h"
#include "fahr/fem/body.h"

namespace fahr::fem_service {

void to_fem(const msg::ContactSet& wire, fem::ContactSet& out);

// True if every number of the set the FEM would use is finite: each
// contact's point, normal, hold centre, penetration and force, and the
// tool's pose. A set that is not is refused whole (ServiceStep::take).
bool all_finite(const msg::ContactSet& wire);

void fill_state(const fem::Body& body, std::uint32_t body_id, msg::DeformationState& out);

}  // namespace fahr::fem_service
