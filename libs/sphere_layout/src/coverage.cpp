// Symmetric Hausdorff coverage of a sphere union (see coverage.h).
#include "fahr/sphere_layout/coverage.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "sphere_hash.h"

namespace fahr::sphere_layout {
namespace {

// A sample on sphere i that another sphere covers by less than this (m) is
// still surface: two spheres meeting exactly leave a seam, not a hole.
constexpr double kCoverSlackM = 1e-9;
// How many voxels a union sample walks outward to find free space before it
// counts as sealed in (a crevice between spheres narrower than that).
constexpr int kOuterProbeVoxels = 3;

class VoxelOutside {
 public:
  VoxelOutside(std::span<const Eigen::Vector3d> centres, std::span<const double> radii,
               double voxel, std::size_t max_voxels)
      : voxel_(voxel) {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
    Eigen::Vector3d hi = -lo;
    for (std::size_t i = 0; i < centres.size(); ++i) {
      lo = lo.cwiseMin(centres[i] - Eigen::Vector3d::Constant(radii[i]));
      hi = hi.cwiseMax(centres[i] + Eigen::Vector3d::Constant(radii[i]));
    }
    // Two free voxels around the box so the border is one connected outside.
    origin_ = lo - Eigen::Vector3d::Constant(2.0 * voxel);
    double total = 1.0;
    for (int a = 0; a < 3; ++a) {
      dims_[a] = static_cast<int>(std::ceil((hi[a] - lo[a]) / voxel)) + 5;
      total *= dims_[a];
    }
    if (total > static_cast<double>(max_voxels)) {
      throw std::invalid_argument(
          "coverage: voxel_size_m gives more voxels than max_voxels; raise voxel_size_m");
    }
    state_.assign(static_cast<std::size_t>(total), kFree);
    for (std::size_t s = 0; s < centres.size(); ++s) rasterise(centres[s], radii[s]);
    flood();
  }

  // True if walking from p along dir finds free space connected to the outside.
  bool faces_outside(const Eigen::Vector3d& p, const Eigen::Vector3d& dir) const {
    for (int step = 1; step <= kOuterProbeVoxels; ++step) {
      const std::size_t v = voxel_of(p + (step * voxel_) * dir);
      if (state_[v] == kOccupied) continue;
      return state_[v] == kOutside;
    }
    return false;
  }

 private:
  static constexpr std::uint8_t kFree = 0, kOccupied = 1, kOutside = 2;

  std::size_t index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(dims_.x()) *
               (static_cast<std::size_t>(j) +
                static_cast<std::size_t>(dims_.y()) * static_cast<std::size_t>(k));
  }
  std::size_t voxel_of(const Eigen::Vector3d& p) const {
    int c[3];
    for (int a = 0; a < 3; ++a) {
      c[a] =
          std::clamp(static_cast<int>(std::floor((p[a] - origin_[a]) / voxel_)), 0, dims_[a] - 1);
    }
    return index(c[0], c[1], c[2]);
  }
  void rasterise(const Eigen::Vector3d& c, double r) {
    int lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(0, static_cast<int>(std::floor((c[a] - r - origin_[a]) / voxel_)));
      hi[a] =
          std::min(dims_[a] - 1, static_cast<int>(std::floor((c[a] + r - origin_[a]) / voxel_)));
    }
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) {
          const Eigen::Vector3d centre =
              origin_ + voxel_ * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
          if ((centre - c).squaredNorm() < r * r) state_[index(i, j, k)] = kOccupied;
        }
  }
  void flood() {
    std::vector<std::uint32_t> queue;
    queue.reserve(state_.size() / 4);
    state_[0] = kOutside;
    queue.push_back(0);
    const int nx = dims_.x(), ny = dims_.y(), nz = dims_.z();
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const std::uint32_t v = queue[head];
      const int i = static_cast<int>(v % static_cast<std::uint32_t>(nx));
      const int j =
          static_cast<int>((v / static_cast<std::uint32_t>(nx)) % static_cast<std::uint32_t>(ny));
      const int k = static_cast<int>(v / static_cast<std::uint32_t>(nx * ny));
      const int next[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k},
                              {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
      for (const auto& n : next) {
        if (n[0] < 0 || n[1] < 0 || n[2] < 0 || n[0] >= nx || n[1] >= ny || n[2] >= nz) continue;
        const std::size_t w = index(n[0], n[1], n[2]);
        if (state_[w] != kFree) continue;
        state_[w] = kOutside;
        queue.push_back(static_cast<std::uint32_t>(w));
      }
    }
  }

  double voxel_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  Eigen::Vector3i dims_ = Eigen::Vector3i::Ones();
  std::vector<std::uint8_t> state_;
};

// Fibonacci lattice on the unit sphere: near-uniform, deterministic.
Eigen::Vector3d fibonacci_direction(std::size_t k, std::size_t n) {
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  const double z = 1.0 - (2.0 * static_cast<double>(k) + 1.0) / static_cast<double>(n);
  const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
  const double phi = golden * static_cast<double>(k);
  return {rho * std::cos(phi), rho * std::sin(phi), z};
}

}  // namespace

CoverageReport measure_coverage(std::span<const Eigen::Vector3d> centres_m,
                                std::span<const double> radii_m,
                                const geometry::SurfaceMesh& boundary,
                                const geometry::SignedDistanceField& boundary_sdf,
                                const CoverageSettings& settings, CoverageOutliers* outliers) {
  if (centres_m.empty() || centres_m.size() != radii_m.size() || boundary.triangle_count() == 0) {
    throw std::invalid_argument(
        "coverage: no spheres, or no boundary triangles, or centres and radii differ in count");
  }
  if (!(settings.sample_spacing_m > 0.0) || !(settings.voxel_size_m > 0.0)) {
    throw std::invalid_argument("coverage: sample_spacing_m and voxel_size_m must be > 0 (m)");
  }
  const double max_radius = *std::max_element(radii_m.begin(), radii_m.end());
  const detail::SphereHash hash(centres_m, radii_m,
                                std::max(2.0 * max_radius, 4.0 * settings.sample_spacing_m));
  CoverageReport report;
  if (outliers != nullptr) {
    outliers->boundary_points_m.clear();
    outliers->boundary_normals.clear();
    outliers->boundary_gaps_m.clear();
    outliers->union_points_m.clear();
  }

  // Boundary -> union: a barycentric lattice on every triangle.
  const auto& v = boundary.vertices();
  double sum = 0.0;
  std::vector<double> gaps;
  for (std::size_t t = 0; t < boundary.triangle_count(); ++t) {
    const auto& tri = boundary.triangles()[t];
    const Eigen::Vector3d &a = v[tri[0]], &b = v[tri[1]], &c = v[tri[2]];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int n = std::max(1, static_cast<int>(std::ceil(longest / settings.sample_spacing_m)));
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j) {
        const double u = static_cast<double>(i) / n, w = static_cast<double>(j) / n;
        const Eigen::Vector3d p = a + u * (b - a) + w * (c - a);
        double d = hash.distance_to_union(p, 2.0 * max_radius);
        if (!(d <= 2.0 * max_radius)) d = hash.distance_to_union_brute_force(p);
        d = std::max(d, 0.0);
        sum += d;
        gaps.push_back(d);
        ++report.boundary_samples;
        if (d > report.boundary_to_union_max_m) {
          report.boundary_to_union_max_m = d;
          report.worst_boundary_point_m = p;
        }
        if (outliers != nullptr && d > outliers->threshold_m) {
          outliers->boundary_points_m.push_back(p);
          outliers->boundary_normals.push_back(boundary.face_normals()[t]);
          outliers->boundary_gaps_m.push_back(d);
        }
      }
    }
  }
  report.boundary_to_union_mean_m = sum / static_cast<double>(report.boundary_samples);
  const std::size_t rank =
      gaps.size() - 1 - gaps.size() / 1000;  // nearest rank of the 99.9th percentile
  std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(rank), gaps.end());
  report.boundary_to_union_p999_m = gaps[rank];

  // Union -> boundary: exposed, outward-facing samples of the sphere surfaces.
  const VoxelOutside outside(centres_m, radii_m, settings.voxel_size_m, settings.max_voxels);
  sum = 0.0;
  for (std::size_t s = 0; s < centres_m.size(); ++s) {
    const double r = radii_m[s];
    const double area = 4.0 * std::numbers::pi * r * r;
    const auto n = std::clamp<std::size_t>(
        static_cast<std::size_t>(
            std::ceil(area / (settings.sample_spacing_m * settings.sample_spacing_m))),
        12, settings.max_samples_per_sphere);
    for (std::size_t k = 0; k < n; ++k) {
      const Eigen::Vector3d dir = fibonacci_direction(k, n);
      const Eigen::Vector3d p = centres_m[s] + r * dir;
      if (hash.covered_by_other(p, static_cast<std::uint32_t>(s), kCoverSlackM)) continue;
      if (!outside.faces_outside(p, dir)) continue;
      const double d = std::abs(boundary_sdf.query(p).distance_m);
      sum += d;
      ++report.union_samples;
      if (d > report.union_to_boundary_max_m) {
        report.union_to_boundary_max_m = d;
        report.worst_union_point_m = p;
      }
      if (outliers != nullptr && d > outliers->threshold_m) outliers->union_points_m.push_back(p);
    }
  }
  report.union_to_boundary_mean_m =
      report.union_samples > 0 ? sum / static_cast<double>(report.union_samples) : 0.0;
  return report;
}

}  // namespace fahr::sphere_layout
