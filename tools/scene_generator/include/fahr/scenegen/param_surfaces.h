// Closed surfaces as images of simple parameter domains. Each builder returns
// a closed, manifold, outward-oriented triangle mesh as long as the map is
// injective on its domain; the orientation is fixed from the enclosed volume,
// so callers need not care about the handedness of their parametrisation.
#pragma once

#include <functional>

#include "fahr/scenegen/geometry_types.h"

namespace fahr::scenegen {

// Boundary of the image of the unit cube (u, v, w) in [0, 1]^3, with nu x nv x nw
// cells. Good for slabs and troughs (palate, jaw).
using BoxMap = std::function<Vec3(double u, double v, double w)>;
TriangleMesh make_param_box(const BoxMap& map, int nu, int nv, int nw);

// A box map with its lattice, so the surface and its check see the same grid.
struct ParamBox {
  BoxMap map;
  int nu = 1;
  int nv = 1;
  int nw = 1;
};
TriangleMesh make_param_box(const ParamBox& box);

// Whether the map folds the box over itself at the lattice's resolution:
// every lattice cell is split into six Kuhn tets and the tets whose image has
// zero volume or the opposite orientation to the majority are counted. Zero
// means the map is locally one-to-one on the lattice, so the boundary surface
// cannot fold back over itself (an injective map also needs no two distant
// cells to overlap, which this does not test).
int folded_box_tets(const ParamBox& box);

// The box as a tet mesh: its lattice points as nodes (node (i, j, k) is
// (i * (nv + 1) + j) * (nw + 1) + k, so the u = 0 face is the first
// (nv + 1) * (nw + 1) nodes), each cell split into the six Kuhn tets that
// folded_box_tets checks, every tet of positive volume when the box does not
// fold, and the outward boundary triangles. For thin deformable parts (the
// epiglottis) that a cube grid cannot hold.
MeshedSolid param_box_tets(const ParamBox& box);

// Torus-topology surface: both parameters periodic on [0, 1). Good for rings
// and thick-walled tubes (face around the mouth, larynx and trachea).
using TorusMap = std::function<Vec3(double around, double loop)>;
TriangleMesh make_param_torus(const TorusMap& map, int n_around, int n_loop);

// Sphere-topology surface: `along` in [0, 1] runs from pole to pole, `around`
// in [0, 1) is periodic. map(0, .) and map(1, .) must each be one point.
// Good for swept, capped tools (laryngoscope blades).
using SphereMap = std::function<Vec3(double along, double around)>;
TriangleMesh make_param_sphere(const SphereMap& map, int n_along, int n_around);

// Reverses every triangle when the enclosed volume is negative.
void orient_outward(TriangleMesh& mesh);

}  // namespace fahr::scenegen
