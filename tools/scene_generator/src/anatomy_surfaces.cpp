// Rigid anatomy as parametric closed surfaces (see param_surfaces.h).
#include "fahr/scenegen/anatomy_surfaces.h"

#include <algorithm>
#include <cmath>

#include "fahr/scenegen/param_surfaces.h"
#include "fahr/scenegen/piecewise_linear.h"
#include "fahr/scenegen/tongue_shape.h"
#include "surface_helpers.h"

namespace fahr::scenegen {
namespace {

// Dental arch: the front edge of a slab curves back at its sides by this
// much, so palate and jaw are U-shaped seen from above.
constexpr double kPalateArchSweepBackMm = 6.0;
// Labial edge of a gum ridge is rounded over this fraction of the slab length.
constexpr double kRidgeRoundFraction = 0.08;
constexpr double kRidgeRoundMm = 2.0;

// Seen from above, a slab is the image of (u, lateral) in [0, 1] x [-1, 1]:
// x from arch_x, z = lateral * half_width(u). The front edge (u = 0) is a
// parabola reaching the side edge at a corner; the map only stays one-to-one
// (no part of the slab folded over another) when that corner is convex, i.e.
// when the side edge leaves it less steeply than the parabola arrives:
// half_width'(0) / (length - sweep) < front_half_width / (2 sweep).
double arch_x(double front_x, double length, double sweep_mm, double u, double lateral) {
  return front_x - length * u - sweep_mm * (1.0 - u) * lateral * lateral;
}

// u^power with a finite slope at u = 0: ((u + a)^power - a^power), scaled to
// run from 0 to 1. A bare u^power (power < 1) has an infinite slope at the
// front, which makes the corner above reflex and folds the slab there.
double eased_power(double u, double power, double ease) {
  const double start = std::pow(ease, power);
  return (std::pow(u + ease, power) - start) / (std::pow(1.0 + ease, power) - start);
}
// Chosen so the arch corners are convex with some margin (at the default
// dimensions the thinnest projected cell corner is 5.7 degrees) while the
// half width differs from the bare power by at most 1.0 mm.
constexpr double kPalateWidthEase = 0.2;

}  // namespace

ParamBox palate_box(const PalateParameters& p, double resolution_mm) {
  const auto map = [p](double u, double v, double w) {
    const double lateral = 2.0 * v - 1.0;
    const double x = arch_x(p.front_x_mm, p.length_mm, kPalateArchSweepBackMm, u, lateral);
    const double half_width =
        p.front_half_width_mm +
        (p.back_half_width_mm - p.front_half_width_mm) * eased_power(u, 0.5, kPalateWidthEase);
    // Vault: rises inside the ridge, both across (ridge at the rim) and along
    // (ridge at the front).
    const double across = smoothstep(0.95, 0.45, std::abs(lateral));
    const double along = smoothstep(0.0, 0.3, u);
    double underside = p.gum_ridge_y_mm + p.vault_depth_mm * across * along;
    if (u < kRidgeRoundFraction) {
      const double r = 1.0 - u / kRidgeRoundFraction;
      underside += kRidgeRoundMm * r * r;
    }
    return Vec3(x, underside + (p.top_y_mm - underside) * w, lateral * half_width);
  };
  const double width = 2.0 * p.back_half_width_mm;
  return {map, cells_for(p.length_mm, resolution_mm), cells_for(width, resolution_mm),
          cells_for(p.top_y_mm - p.gum_ridge_y_mm, 2.0 * resolution_mm)};
}

TriangleMesh make_palate(const PalateParameters& p, double resolution_mm) {
  return make_param_box(palate_box(p, resolution_mm));
}

double ellipse_distance(const ArchEllipse& e, double x_mm, double z_mm) {
  const double u = (x_mm - e.centre_x_mm) / e.a_mm;
  const double v = z_mm / e.b_mm;
  const double rho = std::sqrt(u * u + v * v);
  // |grad rho| = sqrt(u^2 / a^2 + v^2 / b^2) / rho; distance ~ (rho - 1) / |grad rho|.
  const double g = std::sqrt(u * u / (e.a_mm * e.a_mm) + v * v / (e.b_mm * e.b_mm));
  if (g < 1e-12) return -std::min(e.a_mm, e.b_mm);  // the centre
  return (rho - 1.0) * rho / g;
}

ArchEllipse mandible_outer(const JawParameters& p) {
  return {p.front_x_mm - p.length_mm, p.length_mm, p.back_half_width_mm};
}

ArchEllipse mandible_inner(const JawParameters& p, double y_mm) {
  const double top = p.ridge_y_mm - p.lingual_drop_mm;
  const double w = std::clamp((y_mm - p.bottom_y_mm) / (top - p.bottom_y_mm), 0.0, 1.0);
  const double chin = p.symphysis_bottom_mm + (p.symphysis_top_mm - p.symphysis_bottom_mm) * w;
  const ArchEllipse outer = mandible_outer(p);
  return {outer.centre_x_mm, outer.a_mm - chin, outer.b_mm - p.body_thickness_mm};
}

namespace {

// A U-shaped bar: u runs along the arch from one end (t = -90 deg) round the
// front (t = 0) to the other end, v from the inner arch to the outer one, w
// from the bottom to the top. inner(w) and outer give the arches; y(x, v, w)
// the height.
template <typename InnerArch, typename Height>
ParamBox arch_bar_box(const ArchEllipse& outer, InnerArch inner, Height height, double arc_mm,
                      double across_mm, double tall_mm, double resolution_mm) {
  const auto map = [outer, inner, height](double u, double v, double w) {
    const double t = (2.0 * u - 1.0) * 0.5 * kPi;
    const ArchEllipse in = inner(w);
    const Eigen::Vector2d a(in.centre_x_mm + in.a_mm * std::cos(t), in.b_mm * std::sin(t));
    const Eigen::Vector2d b(outer.centre_x_mm + outer.a_mm * std::cos(t), outer.b_mm * std::sin(t));
    const Eigen::Vector2d xz = a + v * (b - a);
    return Vec3(xz.x(), height(xz.x(), v, w), xz.y());
  };
  return {map, cells_for(arc_mm, resolution_mm), cells_for(across_mm, 0.5 * resolution_mm),
          cells_for(tall_mm, resolution_mm)};
}

// Length of half an ellipse (Ramanujan's approximation), for the lattice size.
double half_ellipse_mm(double a, double b) {
  return 0.5 * kPi * (3.0 * (a + b) - std::sqrt((3.0 * a + b) * (a + 3.0 * b)));
}

}  // namespace

ParamBox jaw_box(const JawParameters& p, double resolution_mm) {
  // The top: the crest over the outer 60 % of the bar, the lingual edge
  // lingual_drop_mm lower.
  constexpr double kCrestFromV = 0.4;
  const double top_inner = p.ridge_y_mm - p.lingual_drop_mm;
  const auto inner = [p, top_inner](double w) {
    return mandible_inner(p, p.bottom_y_mm + (top_inner - p.bottom_y_mm) * w);
  };
  const auto height = [p](double, double v, double w) {
    const double top = p.ridge_y_mm - p.lingual_drop_mm * (1.0 - smoothstep(0.0, kCrestFromV, v));
    return p.bottom_y_mm + (top - p.bottom_y_mm) * w;
  };
  const ArchEllipse outer = mandible_outer(p);
  return arch_bar_box(outer, inner, height, half_ellipse_mm(outer.a_mm, outer.b_mm),
                      std::max(p.symphysis_bottom_mm, p.body_thickness_mm),
                      p.ridge_y_mm - p.bottom_y_mm, resolution_mm);
}

TriangleMesh make_jaw(const JawParameters& p, double resolution_mm) {
  return make_param_box(jaw_box(p, resolution_mm));
}

ParamBox hyoid_box(const HyoidParameters& p, const FloorParameters& floor,
                   const TongueParameters& tongue, double resolution_mm) {
  const ArchEllipse outer{p.front_x_mm - p.length_mm, p.length_mm, p.half_span_mm};
  const ArchEllipse in{outer.centre_x_mm, p.length_mm - p.thickness_mm,
                       p.half_span_mm - p.thickness_mm};
  const auto inner = [in](double) { return in; };
  const auto height = [p, floor, tongue](double x, double, double w) {
    const double slope = std::sqrt(1.0 + tongue.floor_slope * tongue.floor_slope);
    const double top =
        attachment_plane_y(tongue, x) - (floor.thickness_mm + floor.bone_gap_mm) * slope;
    return top - p.height_mm * (1.0 - w);
  };
  return arch_bar_box(outer, inner, height, half_ellipse_mm(outer.a_mm, outer.b_mm), p.thickness_mm,
                      p.height_mm, 0.5 * resolution_mm);
}

TriangleMesh make_hyoid(const HyoidParameters& p, const FloorParameters& floor,
                        const TongueParameters& tongue, double resolution_mm) {
  return make_param_box(hyoid_box(p, floor, tongue, resolution_mm));
}

TriangleMesh make_face(const FaceParameters& p, double resolution_mm) {
  constexpr double kCheekSweepBackMm = 6.0;  // outer rim lies this far behind the lips
  constexpr double kLipBulgeWidth = 0.15;    // radial fraction over which the lips bulge
  // The lips' free margin is round in section, not a wall meeting the lips'
  // faces at right angles: a half ellipse as deep as the lips are thick,
  // reaching into the opening by half that thickness. Its tangent meets the
  // faces' (both run radially at the rim), so a field's normal turns smoothly
  // around it; a square rim turned it by 90 degrees within one field cell and
  // a blade sliding over it was pushed along two planes in turn.
  const double rim_round_mm = 0.5 * (p.thickness_mm + p.lip_protrusion_mm);
  const RectangleLoop loop{cells_for(p.face_half_width_mm - p.mouth_half_width_mm, resolution_mm),
                           cells_for(p.thickness_mm, 0.5 * resolution_mm)};
  const auto map = [&](double around, double loop_fraction) {
    const double a = 2.0 * kPi * around;
    const auto [radial, axial] = loop.at(loop_index(loop_fraction, loop.size()));
    // Quadratic spacing from the rim outwards: the lips get more rings than the cheeks.
    const double r = radial * radial;
    // The faces start outside the opening by the rim's reach, so the round
    // margin's innermost line is the opening the parameters give.
    const Eigen::Vector2d inner((p.mouth_half_width_mm + rim_round_mm) * std::cos(a),
                                (p.mouth_half_height_mm + rim_round_mm) * std::sin(a));
    const Eigen::Vector2d outer(p.face_half_width_mm * std::cos(a),
                                p.face_half_height_mm * std::sin(a));
    Eigen::Vector2d zy = inner + r * (outer - inner);
    // Cheeks sweep back at the sides only; above and below the mouth the face
    // stays in front of the gums.
    const double dish = kCheekSweepBackMm * r * r * std::cos(a) * std::cos(a);
    const double lips =
        p.lip_protrusion_mm * std::exp(-(r / kLipBulgeWidth) * (r / kLipBulgeWidth));
    const double back = p.back_x_mm - dish;
    const double front = p.back_x_mm + p.thickness_mm + lips - dish;
    double x = back + (front - back) * axial;
    if (radial == 0.0) {
      // The margin: axial runs from the back face (0) round to the front (1).
      const double turn = kPi * axial;
      x = back + (front - back) * 0.5 * (1.0 - std::cos(turn));
      zy -= rim_round_mm * std::sin(turn) * (outer - inner).normalized();
    }
    return Vec3(x, p.mouth_centre_y_mm + zy.y(), zy.x());
  };
  const int n_around = cells_for(2.0 * kPi * p.mouth_half_width_mm, 0.5 * resolution_mm, 24);
  return make_param_torus(map, n_around, loop.size());
}

}  // namespace fahr::scenegen
