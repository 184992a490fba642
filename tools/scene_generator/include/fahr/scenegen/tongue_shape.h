// The neonatal tongue as an implicit solid: an elliptic cross-section swept
// along a curved sagittal mid-line (tip forward under the palate, base
// turning down towards the pharynx), with ellipsoidal end caps, cut by the
// plane of its attachment to the floor of the mouth. Negative inside; the
// value approximates the distance to the surface in mm near the surface.
#pragma once

#include <vector>

#include "fahr/scenegen/geometry_types.h"
#include "fahr/scenegen/scene_parameters.h"

namespace fahr::scenegen {

class TongueShape {
 public:
  explicit TongueShape(const TongueParameters& params);

  double value(const Vec3& p) const;
  Vec3 gradient(const Vec3& p) const;  // central differences
  // Newton steps along the gradient onto the zero level set.
  Vec3 project_to_surface(const Vec3& p) const;

  // Signed distance (mm) to the attachment plane, negative above it (tissue side).
  double attachment_plane_distance(const Vec3& p) const;

  // Conservative bounds of the solid, mm.
  Vec3 lower_bound() const { return lower_; }
  Vec3 upper_bound() const { return upper_; }
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
  double sweep_value(const Vec3& p) const;

  TongueParameters params_;
  std::vector<SpineSample> spine_;
  double length_ = 0.0;
  double tip_cap_mm_ = 0.0;
  double base_cap_mm_ = 0.0;
  Vec3 lower_;
  Vec3 upper_;
};

}  // namespace fahr::scenegen
