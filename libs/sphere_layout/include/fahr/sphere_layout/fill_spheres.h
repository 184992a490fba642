// Sphere filling of a tet mesh (paper 3.1.1, Figure 2): spheres on a coarse
// grid, octree refinement where the boundary crosses a sphere, tets linked by
// proximity, node weights from barycentric coordinates; then, beyond the
// paper, surface-hugging spheres that close the coverage gap (section 4.3).
#pragma once

#include "fahr/geometry/tet_mesh.h"
#include "fahr/sphere_layout/fill_settings.h"
#include "fahr/sphere_layout/sphere_layout.h"

namespace fahr::sphere_layout {

// Deterministic: the same mesh and settings give the same bytes.
// Throws std::invalid_argument (naming what and which setting) for an empty
// mesh, an open or non-manifold boundary, bad settings, or a layout beyond
// settings.max_spheres.
SphereLayout fill_spheres(const geometry::TetMesh& mesh, const FillSettings& settings);

}  // namespace fahr::sphere_layout
