// Index types shared by the tetrahedral and surface meshes.
#pragma once

#include <array>
#include <cstdint>

namespace fahr::geometry {

// Node / vertex index, 0-based. 32 bits: meshes of a haptic scene stay far
// below 2^31 nodes and the smaller index keeps the element arrays compact.
using Index = std::int32_t;

// Four node indices of a tetrahedron, positively oriented:
// det(x1 - x0, x2 - x0, x3 - x0) > 0.
using Tet = std::array<Index, 4>;

// Three vertex indices of a triangle, counter-clockwise seen from outside.
using Triangle = std::array<Index, 3>;

}  // namespace fahr::geometry
