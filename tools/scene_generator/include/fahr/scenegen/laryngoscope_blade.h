// Miller laryngoscope blade with its handle, as one closed surface in the
// tool frame (mm): origin at the blade tip (distal end of the spatula's
// underside, mid-width); the blade runs from the tip along +x to the heel (it
// points along -x); the spatula's underside (the face that presses the
// tongue) faces -y; the flange (web) is on the -z side; the handle leaves the
// heel along -y. The last tip_curve_length_mm of the spatula curve up (+y).
#pragma once

#include "fahr/scenegen/geometry_types.h"
#include "fahr/scenegen/scene_parameters.h"

namespace fahr::scenegen {

// Cross-section: the spatula plate plus the web on one side (an L; the
// Miller's small top flange over the channel is left out so that every
// section is star-shaped and the sweep stays a simple closed surface). The
// section morphs into the round handle through a bend at the heel.
TriangleMesh make_miller_blade(const BladeParameters& p, double resolution_mm);

}  // namespace fahr::scenegen
