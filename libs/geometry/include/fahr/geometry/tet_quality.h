// Per-tetrahedron shape measures and the statistics of a whole mesh. Poor but
// valid tets (slivers) are counted here, never rejected: the FEM decides what
// it can live with.
#pragma once

#include <Eigen/Core>
#include <cstddef>

namespace fahr::geometry {

// A tet counts as a sliver when one of its dihedral angles lies outside
// [5 deg, 175 deg]: such a tet has nearly coplanar faces, makes the element
// stiffness ill-conditioned, and is the usual threshold of mesh-quality
// literature (e.g. Shewchuk, "What is a good linear finite element?", 2002).
inline constexpr double kSliverMinDihedralDeg = 5.0;
inline constexpr double kSliverMaxDihedralDeg = 175.0;

// Radius ratio below which a tet is reported as poorly shaped (needles, caps
// and slivers alike); 1 is the regular tet. TetGen's default quality bound
// (radius-edge ratio 2) keeps every tet above roughly this value.
inline constexpr double kPoorRadiusRatio = 0.1;

// Shape of one tetrahedron at rest.
struct TetShape {
  double volume_m3 = 0.0;         // signed; > 0 for a valid tet
  double min_dihedral_rad = 0.0;  // [0, pi]
  double max_dihedral_rad = 0.0;  // [0, pi]
  double radius_ratio = 0.0;      // 3 * inradius / circumradius, in [0, 1]
};

// Signed volume (m^3) of the tet (x0, x1, x2, x3): positive when x3 lies on
// the side of (x1 - x0) x (x2 - x0).
double signed_volume(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                     const Eigen::Vector3d& x2, const Eigen::Vector3d& x3);

// True when |volume| cannot be told apart from zero in double precision: the
// determinant of edges of length L carries a rounding error of a few
// epsilon * L^3, so smaller volumes are flat tets, whatever their sign.
bool is_flat_volume(double volume_m3, const Eigen::Vector3d& x0, const Eigen::Vector3d& x1,
                    const Eigen::Vector3d& x2, const Eigen::Vector3d& x3);

TetShape tet_shape(const Eigen::Vector3d& x0, const Eigen::Vector3d& x1, const Eigen::Vector3d& x2,
                   const Eigen::Vector3d& x3);

bool is_sliver(const TetShape& shape);

// Statistics over all tets of a mesh.
struct TetQualityStats {
  std::size_t tet_count = 0;
  double min_volume_m3 = 0.0;
  double max_volume_m3 = 0.0;
  double mean_volume_m3 = 0.0;
  double total_volume_m3 = 0.0;
  double min_dihedral_rad = 0.0;
  double max_dihedral_rad = 0.0;
  double min_radius_ratio = 0.0;
  double mean_radius_ratio = 0.0;
  std::size_t sliver_count = 0;  // dihedral outside [kSliverMinDihedralDeg, kSliverMaxDihedralDeg]
  std::size_t poor_radius_ratio_count = 0;  // radius ratio < kPoorRadiusRatio
  std::size_t unreferenced_node_count = 0;  // nodes no tet uses (FEM must fix or drop them)
};

}  // namespace fahr::geometry
