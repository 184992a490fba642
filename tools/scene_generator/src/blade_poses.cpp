// Suggested blade poses; see blade_poses.h.
#include "fahr/scenegen/blade_poses.h"

#include <cmath>

namespace fahr::scenegen {

Vec3 BladePose::apply(const Vec3& p) const {
  constexpr double kPi = 3.14159265358979323846;
  const double a = pitch_deg * kPi / 180.0;
  const double c = std::cos(a);
  const double s = std::sin(a);
  return tip_mm + Vec3(c * p.x() - s * p.y(), s * p.x() + c * p.y(), p.z());
}

std::vector<BladePose> suggested_blade_poses() {
  return {{"initial", 0.0, Vec3(12.0, 0.5, 0.0)}, {"pressing", 8.0, Vec3(-33.0, -0.5, 0.0)}};
}

TriangleMesh transformed(const TriangleMesh& mesh, const BladePose& pose) {
  TriangleMesh out = mesh;
  for (auto& v : out.vertices) v = pose.apply(v);
  return out;
}

}  // namespace fahr::scenegen
