// The airway behind the mouth: see airway_surfaces.h.
#include "fahr/scenegen/airway_surfaces.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fahr/scenegen/piecewise_linear.h"
#include "surface_helpers.h"

namespace fahr::scenegen {
namespace {

double radians(double deg) {
  return deg * kPi / 180.0;
}

// The larynx's axis frame: down the airway, anterior across it, lateral.
struct LarynxFrame {
  Vec3 inlet;
  Vec3 down;
  Vec3 anterior;
};
LarynxFrame larynx_frame(const AirwayParameters& p) {
  const double tilt = radians(p.tilt_deg);
  return {Vec3(p.inlet_x_mm, p.inlet_y_mm, 0.0), Vec3(-std::sin(tilt), -std::cos(tilt), 0.0),
          Vec3(std::cos(tilt), -std::sin(tilt), 0.0)};
}

// Lumen half axes (AP, lateral) at `depth` below the posterior rim: the
// vestibule, the false folds closing in over 2 mm above the vocal folds, the
// glottic slit, the subglottis opening to the round cricoid over 2 mm, then
// tapering to the trachea at the first ring.
std::pair<double, double> lumen(const AirwayParameters& p, double depth) {
  const double g = p.glottis_depth_mm;
  const PiecewiseLinear ap = {{g - 2.5, p.vestibule_half_ap_mm},
                              {g, p.glottis_half_length_mm},
                              {g + 2.0, p.subglottis_radius_mm},
                              {p.larynx_length_mm, p.trachea_lumen_radius_mm}};
  const PiecewiseLinear lateral = {{g - 2.5, p.vestibule_half_lateral_mm},
                                   {g, p.glottis_half_width_mm},
                                   {g + 2.0, p.subglottis_radius_mm},
                                   {p.larynx_length_mm, p.trachea_lumen_radius_mm}};
  return {ap(depth), lateral(depth)};
}

// `v` turned with the neck by `share` of the head's extension: extension
// turns the face up, so in the head's frame the neck turns the other way
// (posterior going down), clockwise seen from +z.
Vec3 neck_turn(const AirwayParameters& p, const Vec3& v, double share) {
  const double angle = -radians(p.extension_deg) * share;
  return Vec3(std::cos(angle) * v.x() - std::sin(angle) * v.y(),
              std::sin(angle) * v.x() + std::cos(angle) * v.y(), v.z() + 0.0);  // no -0
}

// How far the inlet lies above its default height, mm.
double larynx_rise_mm(const AirwayParameters& p) {
  return p.inlet_y_mm - AirwayParameters{}.inlet_y_mm;
}

}  // namespace

Vec3 neck_pose(const AirwayParameters& p, const Vec3& neutral) {
  if (p.extension_deg == 0.0) return neutral;  // the neutral head, bit for bit
  const double below = std::clamp((p.pivot_y_mm - neutral.y()) / p.bend_mm, 0.0, 1.0);
  const Vec3 pivot(p.pivot_x_mm, p.pivot_y_mm, 0.0);
  return pivot + neck_turn(p, neutral - pivot, smoothstep(0.0, 1.0, below));
}

GlotticOpening glottic_opening(const AirwayParameters& p) {
  const LarynxFrame f = larynx_frame(p);
  // The larynx lies wholly below the bend: its directions turn by the
  // whole angle.
  GlotticOpening g;
  g.centre = neck_pose(p, f.inlet + (p.glottis_depth_mm - 0.1) * f.down);
  g.normal = neck_turn(p, -f.down, 1.0).normalized();
  g.major_axis = neck_turn(p, f.anterior, 1.0).normalized();
  g.radius_mm = p.glottis_half_length_mm - 0.15;
  g.minor_radius_mm = p.glottis_half_width_mm - 0.1;
  return g;
}

Vec3 larynx_axis_point(const AirwayParameters& p, double depth_mm) {
  const LarynxFrame f = larynx_frame(p);
  return neck_pose(p, f.inlet + depth_mm * f.down);
}

TriangleMesh make_larynx_trachea(const AirwayParameters& p, double resolution_mm) {
  const LarynxFrame f = larynx_frame(p);
  const Vec3 lateral = Vec3::UnitZ();
  const double total = p.larynx_length_mm + p.trachea_length_mm;
  const double top_span = p.fold_rise_mm + total;
  // The vocal folds need a finer step along the axis than the rest.
  const RectangleLoop loop{cells_for(top_span, 0.5 * resolution_mm),
                           cells_for(p.wall_thickness_mm, 0.5 * resolution_mm)};
  const auto map = [&](double around, double loop_fraction) {
    const double a = 2.0 * kPi * around;
    const auto [radial, axial] = loop.at(loop_index(loop_fraction, loop.size()));
    // Oblique inlet: the rim rises in front (the aryepiglottic folds run up
    // from the arytenoids behind to the epiglottis in front).
    const double rim = -p.fold_rise_mm * 0.5 * (1.0 + std::cos(a));
    const double depth = rim + (total - rim) * axial;
    const auto [half_ap, half_lateral] = lumen(p, depth);
    const double wall = p.wall_thickness_mm * radial;
    return neck_pose(p, f.inlet + depth * f.down + (half_ap + wall) * std::cos(a) * f.anterior +
                            (half_lateral + wall) * std::sin(a) * lateral);
  };
  const int n_around = cells_for(2.0 * kPi * (p.vestibule_half_ap_mm + p.wall_thickness_mm),
                                 0.5 * resolution_mm, 24);
  return make_param_torus(map, n_around, loop.size());
}

ParamBox epiglottis_box(const EpiglottisParameters& e, const AirwayParameters& a,
                        double resolution_mm) {
  // Its base just above the larynx's anterior rim.
  const LarynxFrame f = larynx_frame(a);
  const double base_y = (f.inlet - a.fold_rise_mm * f.down).y() + e.base_gap_mm;
  const double lean = std::tan(radians(e.lean_back_deg));
  const double curl = radians(e.curl_deg);
  const auto map = [e, a, base_y, lean, curl](double u, double v, double w) {
    const double y = base_y + e.length_mm * u;
    const double front = e.front_x_mm - lean * e.length_mm * u;
    // Narrow at the base (the petiole), full curl from a third of the way up.
    // The petiole's radius stays well above the leaf's thickness, so the
    // lattice's tets (the deformable epiglottis) keep their shape there.
    const double radius = e.radius_mm * (0.7 + 0.3 * smoothstep(0.0, 0.35, u));
    const double phi = (2.0 * v - 1.0) * curl;
    // The lingual face is the arc; the laryngeal face lies a thickness
    // inside it, towards the curl's centre (posterior).
    const double r = radius - e.thickness_mm * w;
    return neck_pose(a, Vec3(front - radius + r * std::cos(phi), y, r * std::sin(phi)));
  };
  // Cells near cubes (0.75 x 0.9 x 0.6 mm at the 1.5 mm resolution), which
  // the deformable epiglottis's tets need more than the surface needs a
  // finer arc.
  return {map, cells_for(e.length_mm, 0.5 * resolution_mm),
          cells_for(2.0 * curl * e.radius_mm, 0.6 * resolution_mm), 2};
}

TriangleMesh make_epiglottis(const EpiglottisParameters& e, const AirwayParameters& a,
                             double resolution_mm) {
  return make_param_box(epiglottis_box(e, a, resolution_mm));
}

double top_of(const ImplicitSolid& solid, double x_mm, double z_mm) {
  constexpr double kStepMm = 0.1;
  constexpr int kBisections = 30;
  double above = solid.upper_bound().y() + 1.0;
  for (double y = above; y > solid.lower_bound().y(); y -= kStepMm) {
    if (solid.value(Vec3(x_mm, y, z_mm)) < 0.0) {
      double lo = y;  // inside
      double hi = y + kStepMm;
      for (int i = 0; i < kBisections; ++i) {
        const double mid = 0.5 * (lo + hi);
        (solid.value(Vec3(x_mm, mid, z_mm)) < 0.0 ? lo : hi) = mid;
      }
      return lo;
    }
    above = y;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

ParamBox soft_palate_box(const SoftPalateParameters& s, const PalateParameters& palate,
                         const ImplicitSolid& tongue, double resolution_mm) {
  // Beyond this distance from the mid-line the underside stays level: the
  // tongue's sides fall away below it.
  const double kFollowHalfWidthMm = 6.0;
  const double front_x = palate.front_x_mm - palate.length_mm - s.palate_gap_mm;
  const double uvula_from = 1.0 - s.uvula_length_mm / s.length_x_mm;
  const auto map = [s, front_x, uvula_from, &tongue, kFollowHalfWidthMm](double u, double v,
                                                                         double w) {
    const double x = front_x - s.length_x_mm * u;
    const double half_width =
        s.uvula_half_width_mm +
        (s.half_width_mm - s.uvula_half_width_mm) * smoothstep(uvula_from, uvula_from - 0.35, u);
    const double z = (2.0 * v - 1.0) * half_width;
    const double oral =
        top_of(tongue, x, std::min(std::abs(z), kFollowHalfWidthMm)) + s.tongue_gap_mm;
    const double thickness = s.thickness_mm + (s.tip_thickness_mm - s.thickness_mm) * u;
    return Vec3(x, oral + thickness * w, z);
  };
  return {map, cells_for(s.length_x_mm, 0.5 * resolution_mm),
          cells_for(2.0 * s.half_width_mm, resolution_mm), 3};
}

TriangleMesh make_soft_palate(const SoftPalateParameters& s, const PalateParameters& palate,
                              const ImplicitSolid& tongue, double resolution_mm) {
  return make_param_box(soft_palate_box(s, palate, tongue, resolution_mm));
}

double pharynx_wall_x(double y_mm, double larynx_rise_mm) {
  // Estimates fitted to the airway's published diameters behind the soft
  // palate and the tongue (meshes/neonatal/README.md): the wall slopes back
  // going down, and behind the larynx it leaves room for the hypopharynx.
  static const PiecewiseLinear kWall = {{-62.0, -72.0}, {-32.0, -69.0}, {-24.0, -66.0},
                                        {-20.0, -62.5}, {-14.0, -59.5}, {-8.0, -57.5},
                                        {2.0, -51.0},   {14.0, -48.0}};
  // A raised larynx takes the hypopharynx up with it: below y -20 the wall
  // is the default wall larynx_rise_mm lower, above y -8 it is unchanged,
  // blended linearly between.
  const double share = std::clamp((-8.0 - y_mm) / 12.0, 0.0, 1.0);
  return kWall(y_mm - share * larynx_rise_mm);
}

double posed_pharynx_wall_x(const AirwayParameters& p, double y_mm) {
  const double rise = larynx_rise_mm(p);
  if (p.extension_deg == 0.0) return pharynx_wall_x(y_mm, rise);
  // The wall's posed mid-line, walked down until it crosses y.
  constexpr double kStepMm = 0.1;
  Vec3 above = neck_pose(p, Vec3(pharynx_wall_x(40.0, rise), 40.0, 0.0));
  for (double y = 40.0 - kStepMm; y > -120.0; y -= kStepMm) {
    const Vec3 below = neck_pose(p, Vec3(pharynx_wall_x(y, rise), y, 0.0));
    if (below.y() <= y_mm && above.y() >= y_mm) {
      const double t = above.y() > below.y() ? (above.y() - y_mm) / (above.y() - below.y()) : 0.0;
      return above.x() + t * (below.x() - above.x());
    }
    above = below;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

ParamBox pharynx_box(const PharynxParameters& p, const AirwayParameters& airway,
                     double resolution_mm) {
  const auto map = [p, airway](double u, double v, double w) {
    const double y = p.top_y_mm + (p.bottom_y_mm - p.top_y_mm) * u;
    const double centre = pharynx_wall_x(y, larynx_rise_mm(airway)) + p.depth_mm;
    const double phi = (2.0 * v - 1.0) * 0.5 * kPi;  // 0 at the back, +-90 deg at the arms' ends
    const double depth = p.depth_mm + p.thickness_mm * w;
    const double half_width = p.half_width_mm + p.thickness_mm * w;
    return neck_pose(airway, Vec3(centre - depth * std::cos(phi), y, half_width * std::sin(phi)));
  };
  const double arc = 0.5 * kPi * (p.depth_mm + p.half_width_mm);
  return {map, cells_for(p.top_y_mm - p.bottom_y_mm, resolution_mm), cells_for(arc, resolution_mm),
          2};
}

TriangleMesh make_pharynx(const PharynxParameters& p, const AirwayParameters& airway,
                          double resolution_mm) {
  return make_param_box(pharynx_box(p, airway, resolution_mm));
}

}  // namespace fahr::scenegen
