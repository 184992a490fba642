// How well a sphere union stands for a body's boundary: the symmetric
// Hausdorff distance between the boundary surface and the outer surface of
// the union of spheres, both sampled densely and deterministically.
//
//   boundary -> union: for boundary samples p, min_i (|p - c_i| - r_i)^+, the
//     exact distance from p to the union (a tool touching the boundary there
//     is missed by up to this much).
//   union -> boundary: for samples s on sphere surfaces that no other sphere
//     covers and that face the outside (a voxel flood fill from the box border
//     tells outer surface from cavities, which a tool cannot reach), |sdf(s)|
//     (how far the union's surface sits from the real one).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <span>
#include <vector>

#include "fahr/geometry/signed_distance_field.h"
#include "fahr/geometry/surface_mesh.h"

namespace fahr::sphere_layout {

struct CoverageSettings {
  // Largest spacing of samples on boundary triangles and on sphere surfaces, m, > 0.
  double sample_spacing_m = 0.25e-3;
  // Voxel edge of the flood fill that finds the union's outer surface, m, > 0;
  // gaps narrower than this between spheres count as closed.
  double voxel_size_m = 0.25e-3;
  std::size_t max_voxels = std::size_t{48} << 20;  // memory guard, 1 byte each
  std::size_t max_samples_per_sphere = 4096;
};

struct CoverageReport {
  double boundary_to_union_max_m = 0.0;   // m
  double boundary_to_union_mean_m = 0.0;  // m
  double boundary_to_union_p999_m = 0.0;  // 99.9th percentile, m: shows whether the max is one spot
  double union_to_boundary_max_m = 0.0;   // m
  double union_to_boundary_mean_m = 0.0;  // m
  double hausdorff_m() const {
    return boundary_to_union_max_m > union_to_boundary_max_m ? boundary_to_union_max_m
                                                             : union_to_boundary_max_m;
  }
  std::size_t boundary_samples = 0;
  std::size_t union_samples = 0;  // outer-surface samples used
  Eigen::Vector3d worst_boundary_point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d worst_union_point_m = Eigen::Vector3d::Zero();
};

// Optional lists of the samples farther than `threshold_m` (for the closure).
struct CoverageOutliers {
  double threshold_m = 0.0;
  std::vector<Eigen::Vector3d> boundary_points_m;  // with their outward normals below
  std::vector<Eigen::Vector3d> boundary_normals;
  std::vector<double> boundary_gaps_m;  // their distance to the union, m
  std::vector<Eigen::Vector3d> union_points_m;
};

// boundary_sdf must be the signed field of `boundary` (exact queries are used).
// Throws std::invalid_argument for empty input or settings out of range.
CoverageReport measure_coverage(std::span<const Eigen::Vector3d> centres_m,
                                std::span<const double> radii_m,
                                const geometry::SurfaceMesh& boundary,
                                const geometry::SignedDistanceField& boundary_sdf,
                                const CoverageSettings& settings,
                                CoverageOutliers* outliers = nullptr);

}  // namespace fahr::sphere_layout
