// The tongue's FEM body: the swept tongue joined to the floor of the mouth
// under it. The floor is a slab from top_above_plane_mm above the tongue's
// attachment plane down to thickness_mm below it, inside the mandible's
// lingual arch (a bone gap clear of it), narrowing behind the mandible
// towards the hyoid and ending over its greater horns. The tongue reaches
// tongue_overlap_mm below its plane and the floor rises above it, so the two
// are one solid with no seam and no thin gap under the tongue's tip (whose
// underside runs less than 1 mm above the plane). Negative inside; near the
// surface the value approximates the distance in mm.
#pragma once

#include "fahr/scenegen/anatomy_surfaces.h"
#include "fahr/scenegen/implicit_solid.h"
#include "fahr/scenegen/scene_parameters.h"
#include "fahr/scenegen/tongue_shape.h"

namespace fahr::scenegen {

class TongueFloorShape final : public ImplicitSolid {
 public:
  TongueFloorShape(const TongueParameters& tongue, const FloorParameters& floor,
                   const JawParameters& jaw);

  double value(const Vec3& p) const override;
  double tongue_value(const Vec3& p) const;
  double floor_value(const Vec3& p) const;
  Vec3 lower_bound() const override { return lower_; }
  Vec3 upper_bound() const override { return upper_; }
  const TongueShape& tongue() const { return tongue_; }

 private:
  // Half width of the floor's taper at x (infinite in front of it).
  double taper_half_width(double x_mm) const;

  TongueShape tongue_;
  FloorParameters floor_;
  JawParameters jaw_;
  double plane_slope_factor_ = 1.0;  // sqrt(1 + slope^2)
  double taper_start_half_width_ = 0.0;
  Vec3 lower_;
  Vec3 upper_;
};

}  // namespace fahr::scenegen
