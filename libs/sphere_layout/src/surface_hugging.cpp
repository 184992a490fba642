// Surface-hugging closure (see surface_hugging.h).
#include "surface_hugging.h"

#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include "fahr/sphere_layout/coverage.h"

namespace fahr::sphere_layout::detail {
namespace {

// A hugging sphere whose room (the distance from its centre to the surface)
// is below this fraction of r_h is not placed: the body is too thin there for
// a sphere to add coverage without a crowd of tiny ones.
constexpr double kMinRoomFraction = 0.2;
// Where a sphere of radius r_h cannot reach its sample (a sharp edge: the
// other face cuts it), the radius is halved up to this many times, so that a
// smaller sphere fits into the edge.
constexpr int kMaxRadiusHalvings = 3;
// Poisson-disc spacing of the first round as a fraction of the lattice
// spacing: a random-order pick leaves gaps up to about twice its spacing.
constexpr double kPoissonFraction = 0.6;

// The 6 axes and 8 diagonals (unit), in a fixed order for determinism.
const std::array<Eigen::Vector3d, 14> kSearchDirections = [] {
  std::array<Eigen::Vector3d, 14> d;
  int k = 0;
  for (int a = 0; a < 3; ++a) {
    d[static_cast<std::size_t>(k++)] = Eigen::Vector3d::Unit(a);
    d[static_cast<std::size_t>(k++)] = -Eigen::Vector3d::Unit(a);
  }
  for (int m = 0; m < 8; ++m) {
    d[static_cast<std::size_t>(k++)] =
        Eigen::Vector3d((m & 1) ? 1 : -1, (m & 2) ? 1 : -1, (m & 4) ? 1 : -1).normalized();
  }
  return d;
}();

// Spheres added this round, bucketed by cell for the proximity check.
class AddedSpheres {
 public:
  explicit AddedSpheres(double cell) : cell_(cell) {}
  void add(const CandidateSphere& s, const Eigen::Vector3d& anchor) {
    spheres_.push_back(s);
    anchors_.push_back(anchor);
    buckets_[key(cell(s.centre_m))].push_back(spheres_.size() - 1);
  }
  // Distance from p to the nearest surface point a sphere was placed for.
  double anchor_distance(const Eigen::Vector3d& p) const {
    double best = std::numeric_limits<double>::infinity();
    visit(p, [&](std::size_t s) { best = std::min(best, (p - anchors_[s]).norm()); });
    return best;
  }
  double distance(const Eigen::Vector3d& p) const {
    double best = std::numeric_limits<double>::infinity();
    visit(p, [&](std::size_t s) {
      best = std::min(best, (p - spheres_[s].centre_m).norm() - spheres_[s].radius_m);
    });
    return best;
  }

 private:
  template <typename F>
  void visit(const Eigen::Vector3d& p, F&& f) const {
    const Eigen::Vector3i c = cell(p);
    for (int k = -1; k <= 1; ++k)
      for (int j = -1; j <= 1; ++j)
        for (int i = -1; i <= 1; ++i) {
          const auto it = buckets_.find(key(c + Eigen::Vector3i(i, j, k)));
          if (it == buckets_.end()) continue;
          for (const std::size_t s : it->second) f(s);
        }
  }
  Eigen::Vector3i cell(const Eigen::Vector3d& p) const {
    return {static_cast<int>(std::floor(p.x() / cell_)),
            static_cast<int>(std::floor(p.y() / cell_)),
            static_cast<int>(std::floor(p.z() / cell_))};
  }
  static std::int64_t key(const Eigen::Vector3i& c) {
    constexpr std::int64_t kSpan = 1 << 20;  // cells per axis; a body is far smaller
    return ((c.x() + kSpan / 2) * kSpan + (c.y() + kSpan / 2)) * kSpan + (c.z() + kSpan / 2);
  }
  double cell_;
  std::vector<CandidateSphere> spheres_;
  std::vector<Eigen::Vector3d> anchors_;
  std::unordered_map<std::int64_t, std::vector<std::size_t>> buckets_;
};

}  // namespace

void add_surface_hugging_spheres(std::vector<CandidateSphere>& spheres,
                                 const geometry::SurfaceMesh& boundary,
                                 const geometry::SignedDistanceField& boundary_sdf,
                                 double hugging_radius_m, const FillSettings& settings) {
  const double tolerance = settings.hugging_tolerance_m;
  CoverageSettings coverage;
  coverage.sample_spacing_m = settings.hugging_sample_spacing_m;
  coverage.voxel_size_m = settings.hugging_sample_spacing_m;
  const auto level = static_cast<std::uint8_t>(settings.refinement_levels);

  for (int round = 0; round < settings.hugging_rounds; ++round) {
    std::vector<Eigen::Vector3d> centres;
    std::vector<double> radii;
    for (const auto& s : spheres) {
      centres.push_back(s.centre_m);
      radii.push_back(s.radius_m);
    }
    CoverageOutliers outliers;
    outliers.threshold_m = tolerance;
    measure_coverage(centres, radii, boundary, boundary_sdf, coverage, &outliers);
    if (outliers.boundary_points_m.empty() && outliers.union_points_m.empty()) return;

    AddedSpheres added(2.0 * hugging_radius_m);
    // First round: samples closer than the spacing of a triangular lattice of
    // r_h spheres whose holes are within the tolerance are left to their
    // neighbours' spheres (a Poisson-disc pick); later rounds fill what is left.
    const double lattice =
        std::sqrt(3.0) * std::sqrt(hugging_radius_m * hugging_radius_m -
                                   std::pow(std::max(0.0, hugging_radius_m - tolerance), 2.0));
    const double min_spacing = round == 0 ? kPoissonFraction * lattice : 0.0;
    auto push = [&](const CandidateSphere& sphere, const Eigen::Vector3d& anchor) {
      if (spheres.size() >= settings.max_spheres) {
        std::ostringstream message;
        message << "sphere filling: surface-hugging spheres pass max_spheres = "
                << settings.max_spheres
                << " (hugging_tolerance_m = " << settings.hugging_tolerance_m
                << ", refinement_levels = " << settings.refinement_levels
                << "); raise max_spheres or hugging_tolerance_m";
        throw std::invalid_argument(message.str());
      }
      spheres.push_back(sphere);
      added.add(sphere, anchor);
    };
    // The sphere along -direction with radius at most r_try, clipped to the
    // room there; its gap to p is |p - c| - r (+infinity when no room).
    auto attempt = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& direction, double r_try,
                       CandidateSphere& out) {
      const Eigen::Vector3d c = p - r_try * direction;
      const double r = std::min(r_try, -boundary_sdf.query_exact(c).distance_m);
      if (!(r >= kMinRoomFraction * r_try)) return std::numeric_limits<double>::infinity();
      out = CandidateSphere{c, r, level, SphereOrigin::kHugging};
      return (p - c).norm() - r;
    };
    auto place = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& outward, double current_gap) {
      if (added.distance(p) <= tolerance || added.anchor_distance(p) < min_spacing) return;
      CandidateSphere sphere;
      double r_try = hugging_radius_m;
      for (int halving = 0; halving <= kMaxRadiusHalvings; ++halving, r_try *= 0.5) {
        if (attempt(p, outward, r_try, sphere) <= tolerance) {
          push(sphere, p);
          return;
        }
      }
      // A fold or a thin fin, where the face normal leads out of the body at
      // once: try fixed directions and keep the sphere that comes closest.
      CandidateSphere best;
      double best_gap = std::min(current_gap, added.distance(p));
      for (const Eigen::Vector3d& direction : kSearchDirections) {
        r_try = hugging_radius_m;
        for (int halving = 0; halving <= kMaxRadiusHalvings; ++halving, r_try *= 0.5) {
          const double gap = attempt(p, direction, r_try, sphere);
          if (gap < best_gap) {
            best_gap = gap;
            best = sphere;
          }
        }
      }
      if (best.radius_m > 0.0) push(best, p);
    };
    for (std::size_t k = 0; k < outliers.boundary_points_m.size(); ++k) {
      place(outliers.boundary_points_m[k], outliers.boundary_normals[k],
            outliers.boundary_gaps_m[k]);
    }
    for (const Eigen::Vector3d& u : outliers.union_points_m) {
      const geometry::SdfSample s = boundary_sdf.query_exact(u);
      place(s.closest_point_m, s.normal, std::numeric_limits<double>::infinity());
    }
  }
}

}  // namespace fahr::sphere_layout::detail
