// Grid and octree filling (see octree_fill.h).
#include "octree_fill.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace fahr::sphere_layout::detail {
namespace {

constexpr double kHalfDiagonalPerEdge = 0.8660254037844386;  // sqrt(3)/2

struct Filler {
  const geometry::SignedDistanceField& sdf;
  const FillSettings& settings;
  std::vector<CandidateSphere>& out;

  void budget_check() const {
    if (out.size() < settings.max_spheres) return;
    std::ostringstream message;
    message << "sphere filling: more than max_spheres = " << settings.max_spheres
            << " spheres (volume_ratio = " << settings.volume_ratio
            << ", refinement_levels = " << settings.refinement_levels
            << "); raise max_spheres, raise volume_ratio or lower refinement_levels";
    throw std::invalid_argument(message.str());
  }

  void visit(const Eigen::Vector3d& centre, double edge, int level) {
    const double r = kHalfDiagonalPerEdge * edge;
    const double d = sdf.query_exact(centre).distance_m;
    if (d >= r) return;  // entirely outside
    if (d <= -r) {       // entirely inside
      budget_check();
      out.push_back({centre, r, static_cast<std::uint8_t>(level), SphereOrigin::kGrid});
      return;
    }
    if (level < settings.refinement_levels) {
      const double child = 0.5 * edge;
      for (int k = 0; k < 8; ++k) {
        const Eigen::Vector3d offset((k & 1) ? 0.5 : -0.5, (k & 2) ? 0.5 : -0.5,
                                     (k & 4) ? 0.5 : -0.5);
        visit(centre + child * offset, child, level + 1);
      }
      return;
    }
    if (-d >= settings.min_radius_fraction * r && d < 0.0) {
      budget_check();
      out.push_back({centre, -d, static_cast<std::uint8_t>(level), SphereOrigin::kGrid});
    }
  }
};

}  // namespace

std::vector<CandidateSphere> octree_fill(const geometry::SignedDistanceField& boundary_sdf,
                                         const Eigen::Vector3d& box_min_m,
                                         const Eigen::Vector3d& box_max_m, double coarse_radius_m,
                                         const FillSettings& settings) {
  const double edge = coarse_radius_m / kHalfDiagonalPerEdge;
  const Eigen::Vector3d extent = box_max_m - box_min_m;
  Eigen::Vector3i cells;
  double cell_count = 1.0;
  for (int a = 0; a < 3; ++a) {
    cells[a] = std::max(1, static_cast<int>(std::ceil(extent[a] / edge)));
    cell_count *= cells[a];
  }
  // Coarse cells each hold at most one sphere; refusing a grid far beyond the
  // budget early keeps a bad ratio from running for minutes.
  if (cell_count > 64.0 * static_cast<double>(settings.max_spheres)) {
    std::ostringstream message;
    message << "sphere filling: volume_ratio = " << settings.volume_ratio << " gives " << cell_count
            << " coarse cells, far beyond max_spheres = " << settings.max_spheres;
    throw std::invalid_argument(message.str());
  }
  // The grid is centred on the box, so the result does not depend on where
  // the box starts.
  const Eigen::Vector3d origin = 0.5 * (box_min_m + box_max_m) - 0.5 * edge * cells.cast<double>();
  std::vector<CandidateSphere> out;
  Filler filler{boundary_sdf, settings, out};
  for (int k = 0; k < cells.z(); ++k) {
    for (int j = 0; j < cells.y(); ++j) {
      for (int i = 0; i < cells.x(); ++i) {
        const Eigen::Vector3d centre = origin + edge * Eigen::Vector3d(i + 0.5, j + 0.5, k + 0.5);
        filler.visit(centre, edge, 0);
      }
    }
  }
  return out;
}

}  // namespace fahr::sphere_layout::detail
