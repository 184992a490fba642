// SignedDistanceField: exact distances on grid nodes, trilinear far field,
// exact BVH answers in a band; sign from angle-weighted pseudo-normals
// (Baerentzen and Aanaes, "Signed distance computation using the angle
// weighted pseudonormal", IEEE TVCG 11(3), 2005).
#include "fahr/geometry/signed_distance_field.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "sdf_cache.h"

namespace fahr::geometry {
namespace {

// sqrt(3): the largest distance from a point to a corner of its grid cell,
// in cells. The distance field is 1-Lipschitz, so a trilinear value is within
// sqrt(3) cells of the true distance when the node values are exact.
constexpr double kCellDiagonal = 1.7320508075688772;

// Relative slack on BVH search bounds derived from neighbouring distances:
// the bound is a mathematical upper bound, the slack only absorbs the
// rounding of the sums that computed it.
constexpr double kBoundSlack = 1e-9;

// Distances below this fraction of the surface's size are "on the surface":
// the direction p - closest point is then rounding noise, and the normal
// comes from the feature's pseudo-normal instead.
constexpr double kOnSurfaceRelative = 1e-12;

std::string topology_text(const SurfaceTopology& t) {
  return std::to_string(t.boundary_edge_count) + " boundary edges, " +
         std::to_string(t.non_manifold_edge_count) + " non-manifold edges, " +
         std::to_string(t.inconsistent_edge_count) + " inconsistently oriented edges, " +
         std::to_string(t.non_manifold_vertex_count) + " non-manifold vertices, " +
         std::to_string(t.folded_edge_count) + " folded (zero-thickness) edges";
}

// The answer to a non-finite query point: NaN distance, so the caller's own
// validation (not a grid index) catches it.
SdfSample invalid_sample(const Eigen::Vector3d& p) {
  return SdfSample{std::numeric_limits<double>::quiet_NaN(), Eigen::Vector3d::UnitZ(), p, false};
}

}  // namespace

SignedDistanceField::SignedDistanceField(const SurfaceMesh& surface, const SdfOptions& options)
    : triangles_(surface.triangles()),
      face_normals_(surface.face_normals()),
      vertex_normals_(surface.vertex_normals()),
      edge_normals_(surface.edge_normals()),
      bvh_(surface),
      signed_(!options.unsigned_mode) {
  if (surface.triangle_count() == 0) {
    throw std::invalid_argument("signed distance field: the surface has no triangles");
  }
  if (!(options.cell_size_m > 0.0) || !std::isfinite(options.cell_size_m)) {
    throw std::invalid_argument("signed distance field: cell_size_m must be positive, got " +
                                std::to_string(options.cell_size_m));
  }
  if (!(options.exact_band_cells >= 0.0) || !(options.margin_m >= 0.0)) {
    throw std::invalid_argument(
        "signed distance field: exact_band_cells and margin_m must be >= 0");
  }
  if (signed_ && (!surface.is_closed() || !surface.is_manifold() || surface.topology().folded())) {
    throw std::invalid_argument(
        "signed distance field: the surface is not a closed manifold without folds (" +
        topology_text(surface.topology()) +
        "), so it has no inside; repair it, or set "
        "SdfOptions::unsigned_mode for unsigned distances");
  }
  cell_size_m_ = options.cell_size_m;
  band_m_ = options.exact_band_cells * cell_size_m_;
  const Eigen::Vector3d extent = surface.bounds_max() - surface.bounds_min();
  on_surface_m_ = kOnSurfaceRelative * std::max(extent.norm(), cell_size_m_);
  // Points outside the grid must be farther than the band, so their
  // clamped estimate is never needed within it.
  const double margin = std::max(options.margin_m, band_m_ + 2.0 * cell_size_m_);
  origin_ = surface.bounds_min() - Eigen::Vector3d::Constant(margin);
  const Eigen::Vector3d span = extent + Eigen::Vector3d::Constant(2.0 * margin);
  double node_count = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double cells = std::ceil(span[axis] / cell_size_m_);
    node_count *= cells + 1.0;
    if (node_count > static_cast<double>(options.max_grid_nodes)) {
      throw std::invalid_argument(
          "signed distance field: grid of cell " + std::to_string(cell_size_m_) +
          " m over the surface needs more than max_grid_nodes = " +
          std::to_string(options.max_grid_nodes) + " nodes; use larger cells");
    }
    dims_[axis] = static_cast<int>(cells) + 1;
  }
  if (options.cache_dir.empty()) {
    fill_grid();
  } else {
    fill_grid_cached(surface, options.cache_dir);
  }
}

double SignedDistanceField::exact_node(const Eigen::Vector3d& p, double bound) const {
  BvhClosestPoint hit = bvh_.closest_point(p, bound * bound);
  if (hit.triangle < 0) {
    hit = bvh_.closest_point(p, std::numeric_limits<double>::infinity());
  }
  const double distance = std::sqrt(hit.distance_squared);
  return signed_ ? sign_of(p, hit) * distance : distance;
}

void SignedDistanceField::fill_grid_cached(const SurfaceMesh& surface,
                                           const std::filesystem::path& dir) {
  detail::SdfGridIdentity identity;
  identity.vertices = surface.vertices();
  identity.triangles = surface.triangles();
  identity.cell_size_m = cell_size_m_;
  identity.band_m = band_m_;
  identity.signed_field = signed_;
  identity.origin = origin_;
  identity.dims = dims_;
  const std::uint64_t key = detail::sdf_grid_key(identity);
  const std::size_t count = static_cast<std::size_t>(dims_.x()) *
                            static_cast<std::size_t>(dims_.y()) *
                            static_cast<std::size_t>(dims_.z());
  std::string why;
  if (detail::read_sdf_grid(dir, key, count, values_, why)) {
    // Recompute a spread of nodes: a grid from code that changed without
    // bumping the grid version, or a file that is someone else's with our
    // name and checksum, is caught here. The bounded and the open search may
    // reach the closest point through different triangles of a shared edge,
    // so the comparison allows rounding.
    constexpr std::size_t kChecks = 64;
    bool agrees = true;
    for (std::size_t n = 0; n < kChecks && agrees; ++n) {
      const std::size_t index = (n * 2654435761ULL + n * n * 40503ULL) % count;
      const int i = static_cast<int>(index % static_cast<std::size_t>(dims_.x()));
      const int j = static_cast<int>((index / static_cast<std::size_t>(dims_.x())) %
                                     static_cast<std::size_t>(dims_.y()));
      const int k = static_cast<int>(
          index / (static_cast<std::size_t>(dims_.x()) * static_cast<std::size_t>(dims_.y())));
      const Eigen::Vector3d p = origin_ + cell_size_m_ * Eigen::Vector3d(i, j, k);
      const double fresh = exact_node(p, std::numeric_limits<double>::infinity());
      agrees = std::abs(fresh - values_[index]) <= 1e-12 * (1.0 + std::abs(fresh));
    }
    if (agrees) {
      grid_source_ = SdfGridSource::kCacheHit;
      return;
    }
    why = detail::sdf_cache_file(dir, key).string() +
          ": its values differ from freshly computed nodes (stale grid code?)";
  }
  fill_grid();
  std::string write_why;
  if (detail::write_sdf_grid(dir, key, values_, write_why)) {
    grid_source_ = SdfGridSource::kBuiltAndCached;
  } else {
    why += (why.empty() ? "" : "; ") + write_why;
  }
  if (!why.empty()) cache_note_ = "field cache: " + why;
}

void SignedDistanceField::fill_grid() {
  values_.assign(static_cast<std::size_t>(dims_.x()) * static_cast<std::size_t>(dims_.y()) *
                     static_cast<std::size_t>(dims_.z()),
                 0.0);
  std::size_t index = 0;
  for (int k = 0; k < dims_.z(); ++k) {
    for (int j = 0; j < dims_.y(); ++j) {
      double previous = std::numeric_limits<double>::infinity();
      for (int i = 0; i < dims_.x(); ++i, ++index) {
        const Eigen::Vector3d p = origin_ + cell_size_m_ * Eigen::Vector3d(i, j, k);
        // |d| changes by at most one cell between neighbours: a tight search bound.
        const double bound = (std::abs(previous) + cell_size_m_) * (1.0 + kBoundSlack);
        values_[index] = exact_node(p, bound);
        previous = values_[index];
      }
    }
  }
}

const Eigen::Vector3d& SignedDistanceField::pseudo_normal(
    const BvhClosestPoint& hit) const noexcept {
  const auto t = static_cast<std::size_t>(hit.triangle);
  const Triangle& tri = triangles_[t];
  switch (hit.feature) {
    case TriangleFeature::kVertex0:
      return vertex_normals_[tri[0]];
    case TriangleFeature::kVertex1:
      return vertex_normals_[tri[1]];
    case TriangleFeature::kVertex2:
      return vertex_normals_[tri[2]];
    case TriangleFeature::kEdge01:
      return edge_normals_[t][0];
    case TriangleFeature::kEdge12:
      return edge_normals_[t][1];
    case TriangleFeature::kEdge20:
      return edge_normals_[t][2];
    case TriangleFeature::kFace:
      break;
  }
  return face_normals_[t];
}

double SignedDistanceField::sign_of(const Eigen::Vector3d& p,
                                    const BvhClosestPoint& hit) const noexcept {
  return (p - hit.point).dot(pseudo_normal(hit)) >= 0.0 ? 1.0 : -1.0;
}

SdfSample SignedDistanceField::exact_from(const Eigen::Vector3d& p,
                                          const BvhClosestPoint& hit) const noexcept {
  SdfSample sample;
  sample.exact = true;
  sample.closest_point_m = hit.point;
  const double distance = std::sqrt(hit.distance_squared);
  const double sign = signed_ ? sign_of(p, hit) : 1.0;
  sample.distance_m = sign * distance;
  if (distance > on_surface_m_) {
    sample.normal = sign * (p - hit.point) / distance;
  } else {
    // On the surface: the face normal is the outward direction (pseudo-normals
    // would differ only on edges and vertices, where any of them will do).
    const Eigen::Vector3d& n = face_normals_[static_cast<std::size_t>(hit.triangle)];
    sample.normal = n.squaredNorm() > 0.0 ? n : Eigen::Vector3d::UnitZ();
  }
  return sample;
}

double SignedDistanceField::grid_distance(const Eigen::Vector3d& p) const noexcept {
  if (!p.allFinite()) {
    return std::numeric_limits<double>::quiet_NaN();  // a NaN pose must not index the grid
  }
  if (values_.empty()) {
    return std::numeric_limits<double>::infinity();
  }
  const Eigen::Vector3d top =
      origin_ + cell_size_m_ * (dims_ - Eigen::Vector3i::Ones()).cast<double>();
  const Eigen::Vector3d clamped = p.cwiseMax(origin_).cwiseMin(top);
  const Eigen::Vector3d u = (clamped - origin_) / cell_size_m_;
  int cell[3];
  double f[3];
  for (int axis = 0; axis < 3; ++axis) {
    cell[axis] = std::clamp(static_cast<int>(std::floor(u[axis])), 0, dims_[axis] - 2);
    f[axis] = u[axis] - cell[axis];
  }
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const int di = corner & 1;
    const int dj = (corner >> 1) & 1;
    const int dk = (corner >> 2) & 1;
    const double w = (di ? f[0] : 1.0 - f[0]) * (dj ? f[1] : 1.0 - f[1]) * (dk ? f[2] : 1.0 - f[2]);
    value += w * node_value(cell[0] + di, cell[1] + dj, cell[2] + dk);
  }
  // Beyond the grid (outside the surface by construction) add the distance to the grid.
  return value + (p - clamped).norm();
}

SdfSample SignedDistanceField::query_exact(const Eigen::Vector3d& p) const noexcept {
  if (!p.allFinite()) {
    return invalid_sample(p);
  }
  const BvhClosestPoint hit = bvh_.closest_point(p, std::numeric_limits<double>::infinity());
  if (hit.triangle < 0) {
    return SdfSample{std::numeric_limits<double>::infinity(), Eigen::Vector3d::UnitZ(), p, false};
  }
  return exact_from(p, hit);
}

SdfSample SignedDistanceField::query(const Eigen::Vector3d& p) const noexcept {
  if (!p.allFinite()) {
    return invalid_sample(p);
  }
  const double grid = grid_distance(p);
  const double error_bound = kCellDiagonal * cell_size_m_;
  if (std::abs(grid) <= band_m_ + error_bound) {
    // |d(p) - grid| <= sqrt(3) h, which both bounds the search and makes
    // every point truly within the band take this path.
    const double bound = (std::abs(grid) + error_bound) * (1.0 + kBoundSlack);
    BvhClosestPoint hit = bvh_.closest_point(p, bound * bound);
    if (hit.triangle < 0) {
      hit = bvh_.closest_point(p, std::numeric_limits<double>::infinity());
    }
    return exact_from(p, hit);
  }
  // Far field: trilinear value; the normal is the field's gradient by central differences of one
  // cell.
  SdfSample sample;
  sample.distance_m = grid;
  const double h = 0.5 * cell_size_m_;
  Eigen::Vector3d gradient;
  for (int axis = 0; axis < 3; ++axis) {
    const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(axis);
    gradient[axis] = grid_distance(p + step) - grid_distance(p - step);
  }
  const double norm = gradient.norm();
  sample.normal = norm > 0.0 ? Eigen::Vector3d(gradient / norm) : Eigen::Vector3d::UnitZ();
  sample.closest_point_m = p - grid * sample.normal;
  sample.exact = false;
  return sample;
}

}  // namespace fahr::geometry
