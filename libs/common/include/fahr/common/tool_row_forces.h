// The tool's rows of a ContactSet (every contact but the anatomy's,
// CONTACT_OBSTACLE) summed two ways: their resultant, the tool's push on the
// tissue, and the sum of their magnitudes. Far apart, the rows squeeze the
// tissue from both faces of the blade (docs/design/force-aware-decision.md).
// Shared by the glottic view, fahr_stack_sim_run and the overshoot bench.
#pragma once

#include <Eigen/Core>

#include "contact_set.h"
#include "fahr/common/wire_eigen.h"

namespace fahr::common {

struct ToolRowForces {
  Eigen::Vector3d resultant_n = Eigen::Vector3d::Zero();  // sum of force_n * normal
  double magnitudes_n = 0.0;                              // sum of force_n
};

inline ToolRowForces tool_row_forces(const msg::ContactSet& set) {
  ToolRowForces out;
  for (const msg::Contact& c : set.contacts()) {
    if (c.kind() == msg::CONTACT_OBSTACLE) continue;
    out.resultant_n += c.force_n() * to_eigen(c.normal());
    out.magnitudes_n += c.force_n();
  }
  return out;
}

}  // namespace fahr::common
