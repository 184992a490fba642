// Defaults and the command line of the scene generator: one flag per named
// dimension, so every number in the scene can be changed without a rebuild.
#include "fahr/scenegen/scene_parameters.h"

#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace fahr::scenegen {
namespace {

struct Flag {
  std::string name;  // without the leading "--"
  double* value;
  const char* help;
};

std::vector<Flag> flag_table(SceneParameters& p) {
  auto& t = p.tongue;
  auto& pa = p.palate;
  auto& j = p.jaw;
  auto& f = p.face;
  auto& fl = p.floor;
  auto& h = p.hyoid;
  auto& a = p.airway;
  std::vector<Flag> flags = {
      {"tongue-cell-mm", &t.cell_mm, "background grid cell of the tongue mesher"},
      {"tongue-length-mm", &t.length_mm, "tongue mid-line length, tip to base"},
      {"tongue-width-mm", &t.width_mm, "largest tongue width"},
      {"tongue-dorsum-height-mm", &t.dorsum_height_mm, "mid-line to dorsum"},
      {"tongue-ventral-depth-mm", &t.ventral_depth_mm, "mid-line to floor attachment"},
      {"tongue-tip-x-mm", &t.tip_x_mm, "tongue tip x"},
      {"tongue-tip-y-mm", &t.tip_y_mm, "tongue tip y"},
      {"tongue-floor-y-mm", &t.floor_y_at_x15_mm, "attachment plane height at x = -15"},
      {"tongue-floor-slope", &t.floor_slope, "attachment plane dy/dx"},
      {"tongue-snap-min-dihedral-deg", &t.snap_min_dihedral_deg, "quality floor for snapping"},
      {"tongue-min-node-mass-fraction", &t.min_node_mass_fraction,
       "tets around a node lighter than this fraction of the median node are peeled off"},
      {"palate-front-x-mm", &pa.front_x_mm, "upper gum ridge, labial face"},
      {"palate-length-mm", &pa.length_mm, "hard palate length"},
      {"palate-front-half-width-mm", &pa.front_half_width_mm, "arch half width, front"},
      {"palate-back-half-width-mm", &pa.back_half_width_mm, "arch half width, back"},
      {"palate-ridge-y-mm", &pa.gum_ridge_y_mm, "upper gum ridge crest"},
      {"palate-vault-depth-mm", &pa.vault_depth_mm, "palatal vault depth"},
      {"jaw-front-x-mm", &j.front_x_mm, "lower gum ridge, labial face"},
      {"jaw-length-mm", &j.length_mm, "chin to gonial angle"},
      {"jaw-back-half-width-mm", &j.back_half_width_mm, "half intergonial width"},
      {"jaw-ridge-y-mm", &j.ridge_y_mm, "lower gum ridge crest"},
      {"jaw-bottom-y-mm", &j.bottom_y_mm, "inferior border of the mandible"},
      {"jaw-symphysis-top-mm", &j.symphysis_top_mm, "chin thickness at the gum ridge"},
      {"jaw-symphysis-bottom-mm", &j.symphysis_bottom_mm, "chin thickness at the border"},
      {"jaw-body-thickness-mm", &j.body_thickness_mm, "mandibular body thickness at the angle"},
      {"floor-thickness-mm", &fl.thickness_mm, "floor of the mouth under the tongue plane"},
      {"floor-bone-gap-mm", &fl.bone_gap_mm, "floor to bone clearance at rest"},
      {"floor-back-x-mm", &fl.back_x_mm, "posterior edge of the floor"},
      {"floor-back-half-width-mm", &fl.back_half_width_mm, "half width at the posterior edge"},
      {"floor-tongue-drop-mm", &fl.tongue_drop_mm, "tongue drawn down onto the floor"},
      {"floor-edge-round-mm", &fl.edge_round_mm, "rounding of the floor edges"},
      {"floor-junction-fillet-mm", &fl.junction_fillet_mm, "fillet between tongue and floor"},
      {"floor-attachment-band-mm", &fl.attachment_band_mm, "nodes this close to bone are fixed"},
      {"hyoid-front-x-mm", &h.front_x_mm, "anterior face of the hyoid body"},
      {"hyoid-length-mm", &h.length_mm, "hyoid body front to horn tips"},
      {"hyoid-half-span-mm", &h.half_span_mm, "half the span of the greater horns"},
      {"mouth-half-width-mm", &f.mouth_half_width_mm, "half mouth opening width"},
      {"mouth-half-height-mm", &f.mouth_half_height_mm, "half mouth opening height"},
      {"lip-thickness-mm", &f.thickness_mm, "lip and cheek thickness"},
      {"larynx-inlet-x-mm", &a.inlet_x_mm, "laryngeal inlet centre x"},
      {"larynx-inlet-y-mm", &a.inlet_y_mm, "laryngeal inlet posterior rim y"},
      {"larynx-tilt-deg", &a.tilt_deg, "larynx axis lean, posterior going down"},
      {"larynx-fold-rise-mm", &a.fold_rise_mm,
       "larynx anterior rim above the posterior (negative: below it)"},
      {"head-extension-deg", &a.extension_deg,
       "head extension: the neck's structures turned about the pivot"},
      {"neck-pivot-x-mm", &a.pivot_x_mm, "craniocervical pivot x"},
      {"neck-pivot-y-mm", &a.pivot_y_mm, "craniocervical pivot y"},
      {"glottis-depth-mm", &a.glottis_depth_mm, "vocal folds below the posterior rim"},
      {"glottis-half-length-mm", &a.glottis_half_length_mm, "half the glottis length (AP)"},
      {"glottis-half-width-mm", &a.glottis_half_width_mm, "half the glottic slit width"},
      {"subglottis-radius-mm", &a.subglottis_radius_mm, "cricoid lumen radius"},
      {"trachea-length-mm", &a.trachea_length_mm, "trachea length"},
      {"trachea-lumen-radius-mm", &a.trachea_lumen_radius_mm, "trachea lumen radius"},
      {"epiglottis-length-mm", &p.epiglottis.length_mm, "epiglottis base to tip"},
      {"epiglottis-radius-mm", &p.epiglottis.radius_mm, "epiglottis curl radius"},
      {"epiglottis-curl-deg", &p.epiglottis.curl_deg, "epiglottis curl angle"},
      {"soft-palate-length-x-mm", &p.soft_palate.length_x_mm, "soft palate along x"},
      {"soft-palate-thickness-mm", &p.soft_palate.thickness_mm, "soft palate thickness"},
      {"soft-palate-tongue-gap-mm", &p.soft_palate.tongue_gap_mm, "soft palate above the tongue"},
      {"pharynx-half-width-mm", &p.pharynx.half_width_mm, "pharyngeal lateral walls"},
      {"pharynx-depth-mm", &p.pharynx.depth_mm, "pharyngeal lateral walls' forward reach"},
      {"surface-resolution-mm", &p.surface_resolution_mm, "rigid surface edge length"},
  };
  for (BladeParameters* b : {&p.miller0, &p.miller1}) {
    const std::string prefix = b->name + "-";
    flags.push_back({prefix + "length-mm", &b->length_mm, "blade length tip to heel"});
    flags.push_back({prefix + "tip-width-mm", &b->tip_width_mm, "blade width at the tip"});
    flags.push_back({prefix + "heel-width-mm", &b->heel_width_mm, "blade width at the heel"});
    flags.push_back({prefix + "heel-web-height-mm", &b->heel_web_height_mm, "flange height"});
    flags.push_back({prefix + "handle-length-mm", &b->handle_length_mm, "handle length"});
    flags.push_back({prefix + "handle-diameter-mm", &b->handle_diameter_mm, "handle diameter"});
  }
  return flags;
}

BladeParameters miller_blade(const std::string& name, double length_mm, double tip_width_mm,
                             double heel_width_mm, double tip_web_mm, double heel_web_mm) {
  BladeParameters b;
  b.name = name;
  b.length_mm = length_mm;
  b.tip_width_mm = tip_width_mm;
  b.heel_width_mm = heel_width_mm;
  b.tip_web_height_mm = tip_web_mm;
  b.heel_web_height_mm = heel_web_mm;
  return b;
}

std::string format_number(double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.4g", v);
  return buffer;
}

}  // namespace

SceneParameters default_scene_parameters() {
  SceneParameters p;
  // Miller 0 and 1: lengths and widths are estimates (meshes/neonatal/README.md).
  p.miller0 = miller_blade("miller0", 77.0, 8.0, 10.0, 2.0, 5.0);
  p.miller1 = miller_blade("miller1", 102.0, 9.0, 12.0, 2.5, 6.5);
  return p;
}

bool parse_scene_parameters(const std::vector<std::string>& args, SceneParameters& params,
                            std::string& error, std::string& help) {
  auto flags = flag_table(params);
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--help" || arg == "-h") {
      std::ostringstream out;
      out << "fahr_scene_generator [--flag value]...\n  --out DIR (default " << params.out_dir
          << ")\n";
      for (const auto& f : flags) {
        out << "  --" << f.name << " (default " << format_number(*f.value) << "): " << f.help
            << "\n";
      }
      help = out.str();
      return false;
    }
    if (arg.rfind("--", 0) != 0 || i + 1 >= args.size()) {
      error = "expected --flag value, got '" + arg + "'";
      return false;
    }
    const std::string name = arg.substr(2);
    const std::string& text = args[++i];
    if (name == "out") {
      params.out_dir = text;
      continue;
    }
    bool known = false;
    for (auto& f : flags) {
      if (f.name != name) continue;
      char* end = nullptr;
      const double v = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0') {
        error = std::string("--").append(name).append(": not a number: '").append(text).append("'");
        return false;
      }
      *f.value = v;
      known = true;
    }
    if (!known) {
      error = "unknown flag --" + name + " (see --help)";
      return false;
    }
  }
  return true;
}

std::string describe_parameters(const SceneParameters& params) {
  SceneParameters copy = params;
  std::ostringstream out;
  for (const auto& f : flag_table(copy)) out << f.name << " = " << format_number(*f.value) << "\n";
  return out.str();
}

}  // namespace fahr::scenegen
