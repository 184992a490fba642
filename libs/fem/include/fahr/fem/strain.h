// Strain and inversion of a body's elements, for reports, benches and tests
// (the step itself uses the corotated small strain, body.cpp).
#pragma once

#include <Eigen/Core>
#include <span>

#include "fahr/fem/element_rest.h"

namespace fahr::fem {

// The largest principal Green strain, in magnitude: max |e_i| over the
// eigenvalues e_i of E = (F^T F - I) / 2 for the deformation gradient F.
// 0 at rest and under any rotation; a principal stretch s gives (s^2 - 1)/2.
double principal_green_strain(const Eigen::Matrix3d& deformation_gradient);

// The largest principal_green_strain over the elements of `rest` at
// positions_m (3 per node, m; Body::positions_m()).
double max_principal_green_strain(const ElementRest& rest, std::span<const double> positions_m);

// Elements with det F <= 0 (flat or inverted) at positions_m.
int inverted_element_count(const ElementRest& rest, std::span<const double> positions_m);

}  // namespace fahr::fem
