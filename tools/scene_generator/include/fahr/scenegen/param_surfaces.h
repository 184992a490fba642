// Closed surfaces as images of simple parameter domains. Each builder returns
// a closed, manifold, outward-oriented triangle mesh as long as the map is
// injective on its domain; the orientation is fixed from the enclosed volume,
// so callers need not care about the handedness of their parametrisation.
#pragma once

#include "fahr/scenegen/geometry_types.h"

#include <functional>

namespace fahr::scenegen {

// Boundary of the image of the unit cube (u, v, w) in [0, 1]^3, with nu x nv x nw
// cells. Good for slabs and troughs (palate, jaw).
using BoxMap = std::function<Vec3(double u, double v, double w)>;
TriangleMesh make_param_box(const BoxMap& map, int nu, int nv, int nw);

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
