// Coverage closure beyond the paper (its section 4.3 limitation), internal:
// surface-hugging spheres, tangent to the boundary from inside, added where
// the sphere union is farther than the tolerance from the boundary.
#pragma once

#include <vector>

#include "candidate_sphere.h"
#include "fahr/geometry/signed_distance_field.h"
#include "fahr/geometry/surface_mesh.h"
#include "fahr/sphere_layout/fill_settings.h"

namespace fahr::sphere_layout::detail {

// Each round measures coverage, then walks the outlying samples in their
// (deterministic) order: a boundary sample p with outward normal m gets a
// sphere centred at p - m r_h, its radius clipped to -sdf(centre) so it stays
// inside; an outlying sample of the union's surface gets one at its nearest
// boundary point. Samples already within the tolerance of a sphere added in
// the same round are skipped, which keeps the spheres about r_h apart.
void add_surface_hugging_spheres(std::vector<CandidateSphere>& spheres,
                                 const geometry::SurfaceMesh& boundary,
                                 const geometry::SignedDistanceField& boundary_sdf,
                                 double hugging_radius_m, const FillSettings& settings);

}  // namespace fahr::sphere_layout::detail
