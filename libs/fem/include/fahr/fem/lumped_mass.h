// Lumped (diagonal) mass: each tet gives a quarter of its mass to each node.
#pragma once

#include <span>
#include <vector>

#include "fahr/fem/element_rest.h"

namespace fahr::fem {

// Mass per node, kg; nodes in no tet get 0 (the body treats them as fixed).
std::vector<double> lumped_mass(const ElementRest& rest, std::size_t node_count,
                                double density_kg_per_m3);

}  // namespace fahr::fem
