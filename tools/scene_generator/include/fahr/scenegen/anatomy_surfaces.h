// Rigid anatomy of the neonatal scene as closed surfaces in the head frame
// (mm): hard palate, mandible with the floor of the mouth, face and lips
// around the mouth opening, larynx with epiglottis and trachea.
#pragma once

#include "fahr/scenegen/geometry_types.h"
#include "fahr/scenegen/param_surfaces.h"
#include "fahr/scenegen/scene_parameters.h"

namespace fahr::scenegen {

// The palate is a solid block (maxilla) whose underside is the palatal vault
// and the upper gum ridge; only that underside can touch the tongue or blade.
TriangleMesh make_palate(const PalateParameters& p, double resolution_mm);
// The parameter box behind make_palate, for folded_box_tets.
ParamBox palate_box(const PalateParameters& p, double resolution_mm);

// The jaw is a solid trough: the floor of the mouth just under the tongue's
// attachment plane, the mandibular bodies beside the tongue, the lower gum
// ridge in front of its tip.
TriangleMesh make_jaw(const JawParameters& p, const TongueParameters& tongue, double resolution_mm);
// The parameter box behind make_jaw, for folded_box_tets.
ParamBox jaw_box(const JawParameters& p, const TongueParameters& tongue, double resolution_mm);

// The face is a thick ring around the mouth opening (genus one), lips bulging
// forward at its inner rim and cheeks curving back at its outer rim.
TriangleMesh make_face(const FaceParameters& p, double resolution_mm);

// Larynx and trachea: one thick-walled tube from the laryngeal inlet down;
// the anterior rim rises into the epiglottis, curling towards the tongue base.
TriangleMesh make_larynx_trachea(const AirwayParameters& p, double resolution_mm);

}  // namespace fahr::scenegen
