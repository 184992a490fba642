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
  double min_node_mass_fraction = 0.1;    // lighter boundary nodes have their tets peeled off
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

// Larynx and trachea: one thick-walled tube down an axis leaning back from
// the laryngeal inlet. The lumen is an ellipse (AP by lateral) at every depth:
// the vestibule under the inlet, the vocal folds narrowing it to the glottic
// slit, the round subglottis (cricoid) and the trachea. The inlet's rim is
// oblique: high in front under the epiglottis, down along the aryepiglottic
// folds to the arytenoids behind.
struct AirwayParameters {
  double inlet_x_mm = -58.5;  // centre of the laryngeal inlet (its posterior rim's height)
  double inlet_y_mm = -24.0;
  double tilt_deg = 8.0;              // axis leans posteriorly going down
  double fold_rise_mm = 3.0;          // anterior rim above the posterior (aryepiglottic folds)
  double vestibule_half_ap_mm = 4.0;  // lumen under the inlet
  double vestibule_half_lateral_mm = 3.0;
  double glottis_depth_mm = 8.0;         // vocal folds below the posterior rim
  double glottis_half_length_mm = 2.75;  // glottis 5.5 mm long (AP)
  double glottis_half_width_mm = 1.0;    // open glottic slit, half width
  double subglottis_radius_mm = 2.4;     // cricoid ring lumen
  double larynx_length_mm = 16.0;        // posterior rim to the first tracheal ring
  double trachea_length_mm = 42.0;
  double trachea_lumen_radius_mm = 2.3;  // ~4.6 mm lumen diameter
  double wall_thickness_mm = 1.5;
  // Head extension (0: the neutral head the rest is given for). In the
  // head's frame the neck turns the other way about the craniocervical
  // pivot: larynx, trachea and epiglottis rigidly, the pharyngeal wall from
  // none at the pivot's height to all of it bend_mm below. The pivot is an
  // estimate: behind the pharyngeal wall at the level of the hard palate.
  double extension_deg = 0.0;
  double pivot_x_mm = -62.0;
  double pivot_y_mm = 5.0;
  double bend_mm = 10.0;
};

// Epiglottis: a curled leaf (U in cross-section, its concave laryngeal face
// posterior, the edges curling back: the neonate's omega shape) rising from
// just above the larynx's anterior rim behind the tongue's base.
struct EpiglottisParameters {
  double base_gap_mm = 0.5;    // above the larynx's anterior rim
  double front_x_mm = -53.8;   // lingual face at the mid-line, at its base
  double length_mm = 9.5;      // base to tip along y
  double lean_back_deg = 4.0;  // the tip lies behind the base
  double radius_mm = 2.8;      // curl radius of the cross-section
  double curl_deg = 95.0;      // the edges turn this far round from the mid-line
  double thickness_mm = 1.2;
};

// Soft palate with the uvula: a slab hanging from the hard palate's posterior
// edge and lying on the tongue's dorsum (the neonate's tongue fills the
// mouth), a gap above it; thinning and narrowing back to the uvula.
struct SoftPalateParameters {
  double palate_gap_mm = 0.5;     // behind the hard palate's posterior face
  double length_x_mm = 17.0;      // from the hard palate to the uvula's tip, along x
  double thickness_mm = 4.0;      // at the hard palate
  double tip_thickness_mm = 2.5;  // at the uvula
  double half_width_mm = 10.0;    // at the hard palate
  double uvula_length_mm = 4.5;
  double uvula_half_width_mm = 2.0;
  double tongue_gap_mm = 1.5;  // above the tongue's dorsum at rest
};

// Pharyngeal wall: a C-shaped channel (posterior and lateral walls, open in
// front to the mouth and the larynx) from the nasopharynx down behind the
// larynx. Its posterior face's x at each height is a profile (airway
// dimensions in meshes/neonatal/README.md).
struct PharynxParameters {
  double top_y_mm = 14.0;
  double bottom_y_mm = -62.0;
  double depth_mm = 6.0;        // the lateral walls reach this far forward
  double half_width_mm = 10.0;  // lateral walls from the mid-line
  double thickness_mm = 3.0;
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
  EpiglottisParameters epiglottis;
  SoftPalateParameters soft_palate;
  PharynxParameters pharynx;
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
