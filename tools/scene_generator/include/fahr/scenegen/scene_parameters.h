// Every dimension of the generated neonatal scene, in millimetres (mm) or
// degrees (deg), with its default. The sources of the defaults are listed in
// meshes/neonatal/README.md. World frame: the anatomical head frame, +x
// anterior, +y superior, +z to the patient's right (right-handed), origin at
// the centre of the mouth opening between the lips.
#pragma once

#include <string>
#include <vector>

namespace fahr::scenegen {

struct TongueParameters {
  double cell_mm = 2.45;           // edge of the background cube grid; sets the tet count
  double length_mm = 40.0;         // arc length of the tongue's mid-line, tip to base
  double width_mm = 25.0;          // largest width, near the base
  double dorsum_height_mm = 8.0;   // mid-line to dorsum, mid-tongue
  double ventral_depth_mm = 12.0;  // mid-line down to the floor attachment, mid-tongue
  double tip_x_mm = -9.0;          // anterior tip, behind the lower gum ridge
  double tip_y_mm = -2.5;
  double floor_y_at_x15_mm = -9.5;        // attachment plane (floor of mouth) height at x = -15 mm
  double floor_slope = 0.42;              // dy/dx of the attachment plane (rises anteriorly)
  double snap_min_dihedral_deg = 8.0;     // boundary snapping never goes below this
  double snap_min_volume_fraction = 0.1;  // ... nor below this fraction of a grid tet
};

struct PalateParameters {
  double front_x_mm = -1.5;  // labial face of the upper gum ridge
  double length_mm = 26.0;   // hard palate, incisive point to posterior margin
  double front_half_width_mm = 9.0;
  double back_half_width_mm = 15.0;
  double gum_ridge_y_mm = 7.5;  // crest of the upper gum ridge
  double vault_depth_mm = 2.0;  // rise of the palatal vault above the ridge line
  double top_y_mm = 17.0;       // top of the (solid) maxilla block
};

// The mandible as a U-shaped bar seen from above: its outer (labial) and
// inner (lingual) faces are elliptic arcs about one centre on the mid-line,
// from one gonial angle round the chin to the other. The floor of the mouth
// (part of the tongue's FEM body) spans the inside of the arch.
struct JawParameters {
  double front_x_mm = -1.0;           // labial face of the chin and lower gum ridge
  double length_mm = 34.0;            // chin to the intergonial line along x (outer arch)
  double back_half_width_mm = 31.8;   // half the intergonial width (outer arch at its ends)
  double ridge_y_mm = -5.5;           // crest of the lower gum ridge
  double bottom_y_mm = -24.0;         // inferior border of the mandible
  double symphysis_top_mm = 4.5;      // chin thickness at the gum ridge, labial to lingual
  double symphysis_bottom_mm = 11.0;  // ... at the inferior border (the lingual face slopes back)
  double body_thickness_mm = 12.0;    // mandibular body at the gonial angle, across
  double lingual_drop_mm = 2.0;       // lingual edge of the top below the crest
};

// Floor of the mouth (mylohyoid, geniohyoid, sublingual tissue): a slab under
// the tongue's attachment plane, inside the mandible's arch and over the
// hyoid. Meshed with the tongue as one body; fixed only where it meets bone.
struct FloorParameters {
  double thickness_mm = 4.0;         // under the tongue's attachment plane
  double bone_gap_mm = 0.3;          // clearance to the mandible and the hyoid at rest
  double tongue_overlap_mm = 1.0;    // the tongue reaches this far below its plane into the floor
  double top_above_plane_mm = 1.5;   // floor's top above the tongue's plane: the tongue's
                                     // underside runs < 1 mm above the plane near the tip
  double back_x_mm = -47.0;          // posterior edge, over the hyoid's greater horns
  double back_half_width_mm = 10.5;  // half width at the posterior edge
  double taper_start_x_mm = -28.0;   // behind this the floor narrows towards the hyoid
  double attachment_band_mm = 1.2;   // boundary nodes this close to bone are fixed
  double tongue_drop_mm = 2.0;       // the tongue is drawn down this far onto the floor
  double edge_round_mm = 3.0;        // the floor's edges are rounded over about this
  double junction_fillet_mm = 3.0;   // fillet where the tongue's sides meet the floor
};

// Hyoid: a small U-shaped bar (body in front, greater horns running back),
// right under the floor's posterior part; its top follows the floor.
struct HyoidParameters {
  double front_x_mm = -38.0;   // anterior face of the body
  double length_mm = 11.0;     // body front to the tips of the greater horns
  double half_span_mm = 10.0;  // half the distance between the horn tips (outer)
  double thickness_mm = 3.0;   // bar thickness across
  double height_mm = 3.0;      // bar height
};

struct FaceParameters {
  double mouth_half_width_mm = 11.0;  // half the opening between the lip commissures
  double mouth_half_height_mm = 8.0;  // half the lip opening during laryngoscopy
  double mouth_centre_y_mm = 0.5;
  double face_half_width_mm = 38.0;
  double face_half_height_mm = 36.0;
  double back_x_mm = 0.0;          // inner face of the lips and cheeks
  double thickness_mm = 6.0;       // lip and cheek soft tissue
  double lip_protrusion_mm = 3.0;  // lips bulge forward of the cheeks
};

struct AirwayParameters {
  double inlet_x_mm = -62.0;  // centre of the laryngeal inlet
  double inlet_y_mm = -30.0;
  double tilt_deg = 8.0;           // axis leans posteriorly going down
  double larynx_length_mm = 18.0;  // inlet to the first tracheal ring
  double trachea_length_mm = 42.0;
  double inlet_lumen_radius_mm = 3.8;
  double trachea_lumen_radius_mm = 2.3;  // ~4.6 mm lumen diameter
  double wall_thickness_mm = 1.5;
  double epiglottis_height_mm = 12.0;  // free edge above the inlet rim
  double epiglottis_flare_mm = 2.0;    // forward curl of its tip
};

struct BladeParameters {
  std::string name;
  double length_mm = 0.0;  // tip to heel along the spatula
  double tip_width_mm = 0.0;
  double heel_width_mm = 0.0;
  double tip_web_height_mm = 0.0;
  double heel_web_height_mm = 0.0;
  double plate_thickness_mm = 1.2;
  double web_thickness_mm = 1.4;
  double tip_curve_length_mm = 10.0;  // the distal curve of the Miller tip
  double tip_curve_deg = 20.0;
  double handle_diameter_mm = 20.0;
  double handle_length_mm = 100.0;
  double heel_bend_radius_mm = 6.0;
};

struct SceneParameters {
  std::string out_dir = "meshes/neonatal";
  TongueParameters tongue;
  PalateParameters palate;
  JawParameters jaw;
  FloorParameters floor;
  HyoidParameters hyoid;
  FaceParameters face;
  AirwayParameters airway;
  BladeParameters miller0;
  BladeParameters miller1;
  double surface_resolution_mm = 1.5;  // target edge length of rigid surfaces
};

SceneParameters default_scene_parameters();

// Parses --flag value pairs over the defaults. Returns false and fills
// `error` on an unknown flag or a bad number; --help fills `help` instead.
bool parse_scene_parameters(const std::vector<std::string>& args, SceneParameters& params,
                            std::string& error, std::string& help);

// "key = value" lines of every parameter, for file headers and logs.
std::string describe_parameters(const SceneParameters& params);

}  // namespace fahr::scenegen
