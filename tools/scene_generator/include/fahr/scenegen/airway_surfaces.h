// The airway behind the mouth as closed surfaces in the head frame (mm):
// soft palate with the uvula, pharyngeal wall, epiglottis, larynx (vocal
// folds, glottic opening, aryepiglottic folds) and trachea. Dimensions and
// sources: meshes/neonatal/README.md.
#pragma once

#include "fahr/scenegen/geometry_types.h"
#include "fahr/scenegen/implicit_solid.h"
#include "fahr/scenegen/param_surfaces.h"
#include "fahr/scenegen/scene_parameters.h"

namespace fahr::scenegen {

// Larynx and trachea: one thick-walled tube (AirwayParameters).
TriangleMesh make_larynx_trachea(const AirwayParameters& p, double resolution_mm);
// The larynx axis point `depth_mm` below the posterior rim (the glottis at
// glottis_depth_mm), for the landmarks.
Vec3 larynx_axis_point(const AirwayParameters& p, double depth_mm);

// A point of the neck's structures given for the neutral head, placed for
// the head's extension (AirwayParameters::extension_deg).
Vec3 neck_pose(const AirwayParameters& p, const Vec3& neutral);

// The glottic slit as the scene's glottic_view section gives it (mm): 0.1 mm
// above the folds' edge, 0.15 mm (AP) and 0.1 mm (across) inside it so the
// lumen's facets do not cover it; the normal out of the airway, the major
// axis anterior.
struct GlotticOpening {
  Vec3 centre, normal, major_axis;
  double radius_mm = 0.0, minor_radius_mm = 0.0;
};
GlotticOpening glottic_opening(const AirwayParameters& p);

ParamBox epiglottis_box(const EpiglottisParameters& e, const AirwayParameters& a,
                        double resolution_mm);
TriangleMesh make_epiglottis(const EpiglottisParameters& e, const AirwayParameters& a,
                             double resolution_mm);

// The soft palate lies on the tongue's dorsum at rest: `tongue` is the FEM
// body's shape, whose top it follows at tongue_gap_mm.
ParamBox soft_palate_box(const SoftPalateParameters& s, const PalateParameters& palate,
                         const ImplicitSolid& tongue, double resolution_mm);
TriangleMesh make_soft_palate(const SoftPalateParameters& s, const PalateParameters& palate,
                              const ImplicitSolid& tongue, double resolution_mm);

// x of the posterior pharyngeal wall's anterior face at the mid-line, at
// height y: for the neutral head, and placed for the head's extension. The
// wall behind the larynx rises with it (larynx_rise_mm: the inlet above its
// default height), the wall behind the soft palate stays.
double pharynx_wall_x(double y_mm, double larynx_rise_mm);
double posed_pharynx_wall_x(const AirwayParameters& p, double y_mm);
ParamBox pharynx_box(const PharynxParameters& p, const AirwayParameters& airway,
                     double resolution_mm);
TriangleMesh make_pharynx(const PharynxParameters& p, const AirwayParameters& airway,
                          double resolution_mm);

// Highest y (mm) inside `solid` on the vertical line through (x, z), or NaN.
double top_of(const ImplicitSolid& solid, double x_mm, double z_mm);

}  // namespace fahr::scenegen
