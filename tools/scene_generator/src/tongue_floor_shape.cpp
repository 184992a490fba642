// The tongue joined to the floor of the mouth: see tongue_floor_shape.h.
#include "fahr/scenegen/tongue_floor_shape.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fahr/scenegen/piecewise_linear.h"

namespace fahr::scenegen {
namespace {

// Polynomial smooth maximum and minimum (Quilez): within `k` mm of a crease
// the two values blend, so an edge of the floor is rounded with a radius of
// about k and the crease where the tongue meets the floor gets a fillet.
// Sharp edges and thin wedges are what a sphere tree cannot cover and what
// the grid mesher fills with flat tets.
double smooth_max(double a, double b, double k) {
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::max(a, b) + 0.25 * h * h * k;
}
double smooth_min(double a, double b, double k) {
  const double h = std::max(k - std::abs(a - b), 0.0) / k;
  return std::min(a, b) - 0.25 * h * h * k;
}

}  // namespace

TongueFloorShape::TongueFloorShape(const TongueParameters& tongue, const FloorParameters& floor,
                                   const JawParameters& jaw)
    : tongue_(tongue),
      floor_(floor),
      jaw_(jaw),
      plane_slope_factor_(std::sqrt(1.0 + tongue.floor_slope * tongue.floor_slope)) {
  // The taper starts where the mandible's lingual arch is at the start's x
  // (taken at the floor's mid-depth there).
  const double y_mid = attachment_plane_y(tongue, floor.taper_start_x_mm) -
                       0.5 * floor.thickness_mm * plane_slope_factor_;
  const ArchEllipse inner = mandible_inner(jaw, y_mid);
  const double u = (floor.taper_start_x_mm - inner.centre_x_mm) / inner.a_mm;
  taper_start_half_width_ = inner.b_mm * std::sqrt(std::max(0.0, 1.0 - u * u));

  const ArchEllipse outer = mandible_outer(jaw);
  const double front = outer.centre_x_mm + outer.a_mm;
  const double bottom =
      attachment_plane_y(tongue, floor.back_x_mm) - floor.thickness_mm * plane_slope_factor_;
  lower_ = tongue_.lower_bound().cwiseMin(Vec3(floor.back_x_mm, bottom, -outer.b_mm));
  upper_ =
      tongue_.upper_bound().cwiseMax(Vec3(front, attachment_plane_y(tongue, front), outer.b_mm));
}

double TongueFloorShape::taper_half_width(double x_mm) const {
  if (x_mm >= floor_.taper_start_x_mm) return std::numeric_limits<double>::infinity();
  const double f = (x_mm - floor_.back_x_mm) / (floor_.taper_start_x_mm - floor_.back_x_mm);
  return floor_.back_half_width_mm + (taper_start_half_width_ - floor_.back_half_width_mm) * f;
}

double TongueFloorShape::tongue_value(const Vec3& p) const {
  // The tongue's underside runs within a millimetre or so of the floor's top
  // over most of its length: the tongue is drawn down onto the floor (the
  // union of copies of it lowered by up to `drop`), so the two meet in a
  // crease at its sides instead of a thin wedge of air under it. Behind the
  // mandible (over the hyoid and the vallecula) the root keeps its shape.
  constexpr int kCopies = 6;
  const double drop =
      floor_.tongue_drop_mm * smoothstep(floor_.back_x_mm + 3.0, floor_.back_x_mm + 9.0, p.x());
  double sweep = tongue_.sweep_value(p);
  for (int k = 1; k <= kCopies && drop > 0.0; ++k) {
    sweep = std::min(sweep, tongue_.sweep_value(p + Vec3(0.0, drop * k / kCopies, 0.0)));
  }
  return std::max(sweep, tongue_.attachment_plane_distance(p) - floor_.tongue_overlap_mm);
}

double TongueFloorShape::floor_value(const Vec3& p) const {
  const double below_plane = tongue_.attachment_plane_distance(p);  // > 0 under the plane
  const double k = floor_.edge_round_mm;
  double v =
      smooth_max(-below_plane - floor_.top_above_plane_mm, below_plane - floor_.thickness_mm, k);
  v = smooth_max(
      v, ellipse_distance(mandible_inner(jaw_, p.y()), p.x(), p.z()) + floor_.bone_gap_mm, k);
  v = smooth_max(v, floor_.back_x_mm - p.x(), k);
  const double half_width = taper_half_width(p.x());
  if (std::isfinite(half_width)) {
    const double slope = (taper_start_half_width_ - floor_.back_half_width_mm) /
                         (floor_.taper_start_x_mm - floor_.back_x_mm);
    v = smooth_max(v, (std::abs(p.z()) - half_width) / std::sqrt(1.0 + slope * slope), k);
  }
  return v;
}

double TongueFloorShape::value(const Vec3& p) const {
  return smooth_min(tongue_value(p), floor_value(p), floor_.junction_fillet_mm);
}

}  // namespace fahr::scenegen
