// The sphere layout as the FEM's sphere links: sphere i of the layout is
// sphere i of the links (the ContactSet's sphere ids index both), with the
// same node weights and its rest radius. An adapter library of its own,
// above both: fahr::fem takes any sphere-to-node weights and knows no mesh
// or layout, fahr::sphere_layout is geometry that knows no FEM, and its
// users (the FEM service, the AIST benchmark) must not need a service.
#pragma once

#include "fahr/fem/sphere_links.h"
#include "fahr/sphere_layout/sphere_layout.h"

namespace fahr::layout_links {

// skin_m is added to every radius, m (the AIST benchmark's contact skin;
// the FEM service uses none). Throws std::invalid_argument naming the
// sphere when the FEM refuses its links (a layout the FEM cannot use is a
// bug in the filling, not bad input: SphereLayout checks the same weights
// more tightly).
fem::SphereLinks to_fem_links(const sphere_layout::SphereLayout& layout, double skin_m = 0.0);

}  // namespace fahr::layout_links
