// The Gmsh element table; only the types fahr can skip or read need to be known.
#include "gmsh_element_types.h"

namespace fahr::geometry::detail {

GmshElementType gmsh_element_type(long long type) {
  switch (type) {
    case 15:
      return {0, 1};  // point
    case 1:
      return {1, 2};  // line
    case 8:
      return {1, 3};  // line, 2nd order
    case 26:
      return {1, 4};
    case 27:
      return {1, 5};
    case 28:
      return {1, 6};
    case 2:
      return {2, 3};  // triangle
    case 3:
      return {2, 4};  // quadrangle
    case 9:
      return {2, 6};
    case 10:
      return {2, 9};
    case 16:
      return {2, 8};
    case 20:
      return {2, 9};
    case 21:
      return {2, 10};
    case 22:
      return {2, 12};
    case 23:  // triangle, 4th order
    case 24:  // triangle, 4th order, incomplete
      return {2, 15};
    case 25:
      return {2, 21};
    case 4:
      return {3, 4};  // tetrahedron
    case 5:
      return {3, 8};  // hexahedron
    case 6:
      return {3, 6};  // prism
    case 7:
      return {3, 5};  // pyramid
    case 11:
      return {3, 10};  // tetrahedron, 2nd order
    case 12:
      return {3, 27};
    case 13:
      return {3, 18};
    case 14:
      return {3, 14};
    case 17:
      return {3, 20};
    case 18:
      return {3, 15};
    case 19:
      return {3, 13};
    case 29:
      return {3, 20};
    case 30:
      return {3, 35};
    case 31:
      return {3, 56};
    case 92:
      return {3, 64};
    case 93:
      return {3, 125};
    default:
      return {};
  }
}

}  // namespace fahr::geometry::detail
