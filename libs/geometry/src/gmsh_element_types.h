// Dimension and node count of Gmsh element types (Gmsh reference manual,
// "MSH file format", element types 1-31 and the 92-93 hexahedra).
#pragma once

namespace fahr::geometry::detail {

struct GmshElementType {
  int dimension = -1;  // -1: unknown type
  int node_count = 0;
};

inline constexpr int kGmshLinearTet = 4;

GmshElementType gmsh_element_type(long long type);

}  // namespace fahr::geometry::detail
