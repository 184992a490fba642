// Rigid anatomy of the neonatal scene as closed surfaces in the head frame
// (mm): hard palate, mandible, hyoid, face and lips around the mouth
// opening. The airway behind the mouth is in airway_surfaces.h.
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

// An ellipse in the horizontal (x-z) plane, centred on the mid-line:
// x = centre_x + a cos t, z = b sin t.
struct ArchEllipse {
  double centre_x_mm = 0.0;
  double a_mm = 1.0;  // semi-axis along x
  double b_mm = 1.0;  // semi-axis along z
};
// Signed distance (mm) from (x, z) to the ellipse, to first order (exact for
// a circle, good near the curve); negative inside.
double ellipse_distance(const ArchEllipse& e, double x_mm, double z_mm);

// The mandible's outer (labial) arch, and its inner (lingual) arch at height
// y: the lingual face of the chin slopes back going down, so the inner arch
// is shorter lower down. Both end at the intergonial line (x = centre_x).
ArchEllipse mandible_outer(const JawParameters& p);
ArchEllipse mandible_inner(const JawParameters& p, double y_mm);

// The mandible: a U-shaped bar between its outer and inner arches, from the
// inferior border up to the gum ridge, whose lingual edge drops a little so
// the tongue's tip can lie over it. No floor: the floor of the mouth is
// tissue (part of the tongue's FEM body) attached to its lingual face.
TriangleMesh make_jaw(const JawParameters& p, double resolution_mm);
// The parameter box behind make_jaw, for folded_box_tets.
ParamBox jaw_box(const JawParameters& p, double resolution_mm);

// The hyoid: a small U-shaped bar (body in front, greater horns running
// back) right under the floor of the mouth's posterior part, its top a bone
// gap below the floor's underside.
TriangleMesh make_hyoid(const HyoidParameters& p, const FloorParameters& floor,
                        const TongueParameters& tongue, double resolution_mm);
ParamBox hyoid_box(const HyoidParameters& p, const FloorParameters& floor,
                   const TongueParameters& tongue, double resolution_mm);

// The face is a thick ring around the mouth opening (genus one), lips bulging
// forward at its inner rim and cheeks curving back at its outer rim.
TriangleMesh make_face(const FaceParameters& p, double resolution_mm);

}  // namespace fahr::scenegen
