// Signed distance to a closed surface: a regular grid of exact distances,
// interpolated trilinearly far from the surface, and an exact closest-point
// search through a triangle BVH within a band around it. Positive outside,
// negative inside. Queries allocate nothing.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "fahr/geometry/surface_mesh.h"
#include "fahr/geometry/triangle_bvh.h"

namespace fahr::geometry {

struct SdfOptions {
  // Grid spacing (m), > 0. Far-field error is at most sqrt(3) cells.
  double cell_size_m = 0.001;
  // How far the grid extends beyond the surface's box (m); raised to at least
  // the band plus two cells, so points off the grid are never within the band.
  double margin_m = 0.0;
  // Queries whose true distance lies within this many cells of the surface are
  // answered exactly from the triangles (>= 0).
  double exact_band_cells = 3.0;
  // Open, non-manifold or folded surfaces (SurfaceTopology) have no inside:
  // they are refused unless the caller asks for unsigned distances (>= 0) here.
  bool unsigned_mode = false;
  // Grids with more nodes are refused (memory: 8 bytes per node).
  std::size_t max_grid_nodes = std::size_t{64} << 20;
  // Where grids are kept between runs (empty: not kept). A grid is read back
  // only for the same surface (every vertex and triangle), the same options
  // and the same grid code; a damaged, foreign or stale file is rebuilt and
  // replaced. The values are the computed ones bit for bit, so a cached field
  // answers exactly as a built one.
  std::filesystem::path cache_dir;
};

// How a field got its grid.
enum class SdfGridSource {
  kBuilt,          // computed, not kept (no cache directory, or it could not be written)
  kCacheHit,       // read from the cache directory
  kBuiltAndCached  // computed and written to the cache directory
};

struct SdfSample {
  // Signed distance (m), positive outside; >= 0 in unsigned mode; NaN for a
  // non-finite query point.
  double distance_m = 0.0;
  // Unit outward normal (away from the surface in unsigned mode).
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  // Nearest surface point (m); the estimate p - d n when not exact.
  Eigen::Vector3d closest_point_m = Eigen::Vector3d::Zero();
  // True when answered from the triangles.
  bool exact = false;
};

class SignedDistanceField {
 public:
  SignedDistanceField() = default;
  // Throws std::invalid_argument (message says why) for an empty surface, bad
  // options, or an open, non-manifold or folded surface unless options.unsigned_mode.
  SignedDistanceField(const SurfaceMesh& surface, const SdfOptions& options);

  // Exact within the band, trilinear beyond it. Allocation-free.
  SdfSample query(const Eigen::Vector3d& p) const noexcept;
  // Always exact (BVH search). Allocation-free.
  SdfSample query_exact(const Eigen::Vector3d& p) const noexcept;
  // The grid's trilinear value alone (m), for diagnostics and benchmarks.
  double grid_distance(const Eigen::Vector3d& p) const noexcept;

  bool is_signed() const { return signed_; }
  double cell_size_m() const { return cell_size_m_; }
  double band_m() const { return band_m_; }
  Eigen::Vector3i grid_dimensions() const { return dims_; }  // nodes per axis
  Eigen::Vector3d grid_origin_m() const { return origin_; }
  SdfGridSource grid_source() const { return grid_source_; }
  // Why the cache was not used although asked for (a file refused or not
  // writable); empty otherwise. For the caller's set-up log.
  const std::string& cache_note() const { return cache_note_; }
  const TriangleBvh& bvh() const { return bvh_; }

 private:
  double node_value(int i, int j, int k) const noexcept {
    return values_[static_cast<std::size_t>(i) +
                   static_cast<std::size_t>(dims_.x()) *
                       (static_cast<std::size_t>(j) +
                        static_cast<std::size_t>(dims_.y()) * static_cast<std::size_t>(k))];
  }
  const Eigen::Vector3d& pseudo_normal(const BvhClosestPoint& hit) const noexcept;
  double sign_of(const Eigen::Vector3d& p, const BvhClosestPoint& hit) const noexcept;
  SdfSample exact_from(const Eigen::Vector3d& p, const BvhClosestPoint& hit) const noexcept;
  double exact_node(const Eigen::Vector3d& p, double bound) const;
  void fill_grid();
  void fill_grid_cached(const SurfaceMesh& surface, const std::filesystem::path& dir);

  // The surface's normals are kept (not the mesh) for the sign test.
  std::vector<Triangle> triangles_;
  std::vector<Eigen::Vector3d> face_normals_;
  std::vector<Eigen::Vector3d> vertex_normals_;
  std::vector<std::array<Eigen::Vector3d, 3>> edge_normals_;
  TriangleBvh bvh_;
  bool signed_ = true;
  double cell_size_m_ = 0.0;
  double band_m_ = 0.0;
  double on_surface_m_ =
      0.0;  // below this distance the normal comes from the feature's pseudo-normal
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  Eigen::Vector3i dims_ = Eigen::Vector3i::Zero();
  std::vector<double> values_;  // m, x fastest
  SdfGridSource grid_source_ = SdfGridSource::kBuilt;
  std::string cache_note_;
};

}  // namespace fahr::geometry
