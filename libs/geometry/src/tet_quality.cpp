// Shape measures of one tetrahedron.
#include "fahr/geometry/tet_quality.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace fahr::geometry {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;

// Rounding bound of a 3x3 determinant of edge vectors: each of its six
// triple products carries ~3 rounding errors of epsilon * L^3; 32 epsilon
// leaves a safety factor of about 2 over 6 * 3 = 18 (Shewchuk 1997 gives
// the exact-arithmetic bound this approximates).
constexpr double kFlatVolumeEpsilons = 32.0;

}  // namespace

double signed_volume(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                     const Eigen::Vector3d& x2, const Eigen::Vector3d& x3) {
  return (x1 - x0).cross(x2 - x0).dot(x3 - x0) / 6.0;
}

bool is_flat_volume(double volume_m3, const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                    const Eigen::Vector3d& x2, const Eigen::Vector3d& x3) {
  const double l1 = (x1 - x0).norm();
  const double l2 = (x2 - x0).norm();
  const double l3 = (x3 - x0).norm();
  // The determinant is 6 * volume; its rounding error scales with the product of the edge lengths.
  const double bound =
      kFlatVolumeEpsilons * std::numeric_limits<double>::epsilon() * l1 * l2 * l3 / 6.0;
  return std::abs(volume_m3) <= bound;
}

TetShape tet_shape(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                   const Eigen::Vector3d& x3) {
  TetShape shape;
  shape.volume_m3 = signed_volume(x0, x1, x2, x3);
  const std::array<Eigen::Vector3d, 4> x = {x0, x1, x2, x3};
  // Area-weighted outward normals of the faces opposite each vertex (for a
  // positive tet): faces (1,2,3), (0,3,2), (0,1,3), (0,2,1).
  constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  std::array<Eigen::Vector3d, 4> normals;
  double area_sum = 0.0;
  for (int f = 0; f < 4; ++f) {
    const Eigen::Vector3d& a = x[static_cast<std::size_t>(kFaces[f][0])];
    const Eigen::Vector3d& b = x[static_cast<std::size_t>(kFaces[f][1])];
    const Eigen::Vector3d& c = x[static_cast<std::size_t>(kFaces[f][2])];
    normals[static_cast<std::size_t>(f)] = (b - a).cross(c - a);
    area_sum += 0.5 * normals[static_cast<std::size_t>(f)].norm();
  }
  // Dihedral angle at the edge shared by faces i and j: pi minus the angle of their outward
  // normals.
  shape.min_dihedral_rad = kPi;
  shape.max_dihedral_rad = 0.0;
  for (std::size_t i = 0; i < 4; ++i) {
    for (std::size_t j = i + 1; j < 4; ++j) {
      const double cross_norm = normals[i].cross(normals[j]).norm();
      const double dot = normals[i].dot(normals[j]);
      // atan2 keeps precision near 0 and pi, where acos of a dot product does not.
      const double angle = kPi - std::atan2(cross_norm, dot);
      shape.min_dihedral_rad = std::min(shape.min_dihedral_rad, angle);
      shape.max_dihedral_rad = std::max(shape.max_dihedral_rad, angle);
    }
  }
  // Radius ratio 3 r / R: inradius r = 3 V / (sum of face areas); circumradius
  // R = |a^2 (b x c) + b^2 (c x a) + c^2 (a x b)| / (12 V) with a, b, c the edges from x0.
  const Eigen::Vector3d a = x1 - x0;
  const Eigen::Vector3d b = x2 - x0;
  const Eigen::Vector3d c = x3 - x0;
  const double volume = std::abs(shape.volume_m3);
  const Eigen::Vector3d circ =
      a.squaredNorm() * b.cross(c) + b.squaredNorm() * c.cross(a) + c.squaredNorm() * a.cross(b);
  const double circ_norm = circ.norm();
  if (volume > 0.0 && area_sum > 0.0 && circ_norm > 0.0) {
    const double inradius = 3.0 * volume / area_sum;
    const double circumradius = circ_norm / (12.0 * volume);
    shape.radius_ratio = std::clamp(3.0 * inradius / circumradius, 0.0, 1.0);
  }
  return shape;
}

bool is_sliver(const TetShape& shape) {
  return shape.min_dihedral_rad < kSliverMinDihedralDeg * kDegToRad ||
         shape.max_dihedral_rad > kSliverMaxDihedralDeg * kDegToRad;
}

}  // namespace fahr::geometry
