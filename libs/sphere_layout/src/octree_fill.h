// Grid and octree part of the filling (paper 3.1.1, Figure 2), internal.
#pragma once

#include <vector>

#include "candidate_sphere.h"
#include "fahr/geometry/signed_distance_field.h"
#include "fahr/sphere_layout/fill_settings.h"

namespace fahr::sphere_layout::detail {

// A cell's sphere circumscribes the cube (r = h sqrt(3)/2), so kept cells are
// covered without gaps. A sphere entirely inside the surface is kept; one the
// surface crosses is split into 8 until the finest level, where it is clipped
// to the surface (r = -sdf(centre), tangent from inside) and kept if at least
// min_radius_fraction of the level radius. Cells are visited in a fixed
// order, so the output is deterministic. Throws std::invalid_argument when the
// count passes settings.max_spheres.
std::vector<CandidateSphere> octree_fill(const geometry::SignedDistanceField& boundary_sdf,
                                         const Eigen::Vector3d& box_min_m,
                                         const Eigen::Vector3d& box_max_m, double coarse_radius_m,
                                         const FillSettings& settings);

}  // namespace fahr::sphere_layout::detail
