// A solid given by a function of position, negative inside, whose value
// approximates the distance to its surface (mm) near the surface: what the
// tet mesher meshes.
#pragma once

#include "fahr/scenegen/geometry_types.h"

namespace fahr::scenegen {

class ImplicitSolid {
 public:
  virtual ~ImplicitSolid() = default;

  virtual double value(const Vec3& p) const = 0;
  // Conservative bounds of the solid, mm.
  virtual Vec3 lower_bound() const = 0;
  virtual Vec3 upper_bound() const = 0;

  Vec3 gradient(const Vec3& p) const;  // central differences
  // Newton steps along the gradient onto the zero level set.
  Vec3 project_to_surface(const Vec3& p) const;
};

}  // namespace fahr::scenegen
