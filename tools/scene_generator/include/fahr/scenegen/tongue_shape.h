// The neonatal tongue as an implicit solid: an elliptic cross-section swept
// along a curved sagittal mid-line (tip forward under the palate, base
// turning down towards the pharynx), with ellipsoidal end caps, cut by the
// plane of its attachment to the floor of the mouth. Negative inside; the
// value approximates the distance to the surface in mm near the surface.
#pragma once

#include <vector>

#include "fahr/scenegen/geometry_types.h"
#include "fahr/scenegen/implicit_solid.h"
#include "fahr/scenegen/scene_parameters.h"

namespace fahr::scenegen {

// Height (y, mm) of the tongue's attachment plane at x: the plane where the
// tongue meets the floor of the mouth, rising anteriorly.
double attachment_plane_y(const TongueParameters& params, double x_mm);

class TongueShape final : public ImplicitSolid {
 public:
  explicit TongueShape(const TongueParameters& params);

  // The swept tongue cut by its attachment plane.
  double value(const Vec3& p) const override;
  // The swept tongue alone (no cut).
  double sweep_value(const Vec3& p) const;

  // Signed distance (mm) to the attachment plane, negative above it (tissue side).
  double attachment_plane_distance(const Vec3& p) const;

  Vec3 lower_bound() const override { return lower_; }
  Vec3 upper_bound() const override { return upper_; }
  double midline_length_mm() const { return length_; }

 private:
  struct SpineSample {
    Eigen::Vector2d point;    // (x, y) mm
    Eigen::Vector2d tangent;  // unit, tip towards base
    double arc_mm;
  };
  struct Section {
    double dorsal_mm;   // mid-line to dorsum
    double ventral_mm;  // mid-line downwards
    double half_width_mm;
  };
  Section section_at(double arc_mm) const;

  TongueParameters params_;
  std::vector<SpineSample> spine_;
  double length_ = 0.0;
  double tip_cap_mm_ = 0.0;
  double base_cap_mm_ = 0.0;
  Vec3 lower_;
  Vec3 upper_;
};

}  // namespace fahr::scenegen
