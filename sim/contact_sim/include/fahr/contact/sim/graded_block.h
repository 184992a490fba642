// A block of tissue for tests and benchmarks: a rectilinear grid, fine and
// uniform around the middle of its top face (y = top), growing
// geometrically toward the sides and the bottom (fixed), each cell cut into
// six tetrahedra around its main diagonal (Kuhn), conforming across cells.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "fahr/fem/box_mesh.h"

namespace fahr::contact::sim {

struct GradedBlockSpec {
  double half_width_m = 0.05;        // x and z extent either side of the centre, m, > 0
  double depth_m = 0.05;             // y extent below the top face, m, > 0
  double fine_half_width_m = 0.008;  // uniform region either side of the centre, m
  double fine_depth_m = 0.008;       // uniform region below the top face, m
  double fine_cell_m = 0.0016;       // cell size there, m, > 0
  double growth = 1.35;              // ratio of neighbouring cell sizes outside, >= 1
};

struct BlockScene {
  fem::BodyMesh mesh;
  std::vector<std::uint32_t> fixed_nodes;  // the bottom face
  std::vector<std::uint32_t> top_nodes;    // the top face (y = 0)
};

// Top face at y = 0, centred on x = z = 0.
BlockScene make_graded_block(const GradedBlockSpec& spec);

}  // namespace fahr::contact::sim
