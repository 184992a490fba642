// Box meshes shared by tests and benchmarks: a grid of cells, each split
// into 6 tetrahedra around its main diagonal (Kuhn subdivision), which is
// conforming across cells because every cell uses the same diagonal.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "fahr/fem/element_rest.h"

namespace fahr::fem {

// What Body::create takes, as one value: rest node positions (m) and tets
// in the FEM's index type. Not geometry::TetMesh, the loaded and validated
// rest mesh with its boundary, quality and rest data: the boxes made here
// and the tests' and benches' meshes need none of that.
struct BodyMesh {
  std::vector<Eigen::Vector3d> nodes_m;
  std::vector<Tet> tets;
};

// cells: cell counts along x, y, z (>= 1); size_m: box extent, m; the box
// spans [origin, origin + size]. Node (i, j, k) has index i + (nx+1)(j + (ny+1) k).
BodyMesh make_box_mesh(const std::array<int, 3>& cells, const Eigen::Vector3d& size_m,
                       const Eigen::Vector3d& origin_m = Eigen::Vector3d::Zero());

}  // namespace fahr::fem
