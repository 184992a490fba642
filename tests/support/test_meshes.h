// Small meshes and the neonatal tongue for the tests of the sphere layout
// and of the collision library.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "fahr/geometry/surface_mesh.h"
#include "fahr/geometry/tet_mesh.h"
#include "fahr/sphere_layout/fill_spheres.h"

namespace fahr::test {

// An axis-aligned block [lo, hi] of n^3 cubes, six tets each (Kuhn split), m.
geometry::TetMesh block_tet_mesh(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int n);
// Closed, outward box surface, m.
geometry::SurfaceMesh box_surface(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);
// Icosphere of `subdivisions` (radius in m), outward.
geometry::SurfaceMesh icosphere(const Eigen::Vector3d& centre, double radius, int subdivisions);

// The neonatal tongue in metres (loaded once per process).
const geometry::TetMesh& neonatal_tongue();
// Its default sphere layout (filled once per process).
const sphere_layout::SphereLayout& neonatal_layout();

}  // namespace fahr::test
