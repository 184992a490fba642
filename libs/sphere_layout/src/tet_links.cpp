// Sphere-to-tet links and node weights (see tet_links.h).
#include "tet_links.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>

#include "fahr/geometry/closest_point.h"
#include "fahr/geometry/tet_deformation.h"

namespace fahr::sphere_layout::detail {
namespace {

// A point whose smallest barycentric coordinate is above -this is inside the
// tet: rounding in Dm^-1 (p - x0) on millimetre tets is ~1e-15.
constexpr double kInsideTolerance = 1e-12;
// link_anchored: halvings of (depth_factor - 1) tried before giving up, and
// the smallest surface share worth anchoring for.
constexpr int kAnchorAttempts = 4;
constexpr double kMinAnchorShare = 0.05;

Eigen::Vector3i cell_of(const Eigen::Vector3d& p, const Eigen::Vector3d& origin, double cell,
                        const Eigen::Vector3i& dims) {
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) {
    c[a] = std::clamp(static_cast<int>(std::floor((p[a] - origin[a]) / cell)), 0, dims[a] - 1);
  }
  return c;
}

}  // namespace

TetLinker::TetLinker(const geometry::TetMesh& mesh, int max_linked_tets)
    : mesh_(mesh), max_linked_(max_linked_tets) {
  const auto& x = mesh.rest_positions();
  Eigen::Vector3d lo = x[0], hi = x[0];
  for (const auto& p : x) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  double mean_volume = 0.0;
  for (const auto& r : mesh.rest_data()) mean_volume += r.volume_m3;
  mean_volume /= static_cast<double>(mesh.tet_count());
  cell_m_ = 2.0 * std::cbrt(mean_volume);
  origin_ = lo;
  for (int a = 0; a < 3; ++a) {
    dims_[a] = std::max(1, static_cast<int>(std::ceil((hi[a] - lo[a]) / cell_m_)) + 1);
  }
  const std::size_t cell_count = static_cast<std::size_t>(dims_.x()) * dims_.y() * dims_.z();
  auto index = [&](const Eigen::Vector3i& c) {
    return static_cast<std::size_t>(c.x()) +
           static_cast<std::size_t>(dims_.x()) *
               (static_cast<std::size_t>(c.y()) + static_cast<std::size_t>(dims_.y()) * c.z());
  };
  // Two passes (count, fill): a compressed layout, tets in index order per cell.
  std::vector<std::uint32_t> counts(cell_count + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<std::uint32_t> cursor;
    if (pass == 1) {
      cell_start_.assign(cell_count + 1, 0);
      for (std::size_t c = 0; c < cell_count; ++c) cell_start_[c + 1] = cell_start_[c] + counts[c];
      cell_tets_.resize(cell_start_.back());
      cursor.assign(cell_start_.begin(), cell_start_.end() - 1);
    }
    for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
      const auto& tet = mesh.tets()[t];
      Eigen::Vector3d tlo = x[tet[0]], thi = x[tet[0]];
      for (int k = 1; k < 4; ++k) {
        tlo = tlo.cwiseMin(x[tet[k]]);
        thi = thi.cwiseMax(x[tet[k]]);
      }
      const Eigen::Vector3i a = cell_of(tlo, origin_, cell_m_, dims_);
      const Eigen::Vector3i b = cell_of(thi, origin_, cell_m_, dims_);
      for (int k = a.z(); k <= b.z(); ++k)
        for (int j = a.y(); j <= b.y(); ++j)
          for (int i = a.x(); i <= b.x(); ++i) {
            const std::size_t c = index({i, j, k});
            if (pass == 0) {
              ++counts[c];
            } else {
              cell_tets_[cursor[c]++] = static_cast<std::uint32_t>(t);
            }
          }
    }
  }
  stamp_.assign(mesh.tet_count(), 0);
}

void TetLinker::candidates(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  found_.clear();
  ++current_stamp_;
  const Eigen::Vector3i a = cell_of(lo, origin_, cell_m_, dims_);
  const Eigen::Vector3i b = cell_of(hi, origin_, cell_m_, dims_);
  for (int k = a.z(); k <= b.z(); ++k)
    for (int j = a.y(); j <= b.y(); ++j)
      for (int i = a.x(); i <= b.x(); ++i) {
        const std::size_t c =
            static_cast<std::size_t>(i) +
            static_cast<std::size_t>(dims_.x()) *
                (static_cast<std::size_t>(j) + static_cast<std::size_t>(dims_.y()) * k);
        for (std::uint32_t e = cell_start_[c]; e < cell_start_[c + 1]; ++e) {
          const std::uint32_t t = cell_tets_[e];
          if (stamp_[t] == current_stamp_) continue;
          stamp_[t] = current_stamp_;
          found_.push_back(t);
        }
      }
}

Eigen::Matrix3d TetLinker::rest_edge_inverse(std::uint32_t tet) const {
  const auto& t = mesh_.tets()[tet];
  const auto& x = mesh_.rest_positions();
  return geometry::edge_matrix(x[t[0]], x[t[1]], x[t[2]], x[t[3]]).inverse();
}

Eigen::Vector4d TetLinker::barycentric(std::uint32_t tet, const Eigen::Vector3d& p) const {
  const Eigen::Vector3d b =
      rest_edge_inverse(tet) * (p - mesh_.rest_positions()[mesh_.tets()[tet][0]]);
  return {1.0 - b.sum(), b.x(), b.y(), b.z()};
}

double TetLinker::distance_to_tet(std::uint32_t tet, const Eigen::Vector3d& p) const {
  if (barycentric(tet, p).minCoeff() >= -kInsideTolerance) return 0.0;
  const auto& t = mesh_.tets()[tet];
  const auto& x = mesh_.rest_positions();
  double best = std::numeric_limits<double>::infinity();
  static constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};
  for (const auto& f : kFaces) {
    const auto c = geometry::closest_point_on_triangle(p, x[t[f[0]]], x[t[f[1]]], x[t[f[2]]]);
    best = std::min(best, c.distance_squared);
  }
  return std::sqrt(best);
}

SphereLink TetLinker::link(const Eigen::Vector3d& centre_m, double radius_m, double weight_spread) {
  candidates(centre_m - Eigen::Vector3d::Constant(radius_m),
             centre_m + Eigen::Vector3d::Constant(radius_m));
  std::vector<std::pair<double, std::uint32_t>> near;
  for (const std::uint32_t t : found_) {
    const double d = distance_to_tet(t, centre_m);
    if (d <= radius_m) near.emplace_back(d, t);
  }
  if (near.empty()) {  // a centre outside every tet's reach: the nearest tet of all
    for (std::uint32_t t = 0; t < mesh_.tet_count(); ++t)
      near.emplace_back(distance_to_tet(t, centre_m), t);
  }
  std::sort(near.begin(), near.end());
  if (near.size() > static_cast<std::size_t>(max_linked_))
    near.resize(static_cast<std::size_t>(max_linked_));

  // The holding tet: among those at distance 0 the one with the largest
  // smallest barycentric coordinate (the best conditioned); else the nearest.
  std::size_t hold = 0;
  double best_min = -std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < near.size() && near[k].first == 0.0; ++k) {
    const double m = barycentric(near[k].second, centre_m).minCoeff();
    if (m > best_min) {
      best_min = m;
      hold = k;
    }
  }
  const std::uint32_t hold_tet = near[hold].second;
  const auto& ht = mesh_.tets()[hold_tet];
  const auto& x = mesh_.rest_positions();
  Eigen::Vector4d a = barycentric(hold_tet, centre_m);
  if (a.minCoeff() < 0.0) {  // outside: clamp to the tet, the centre moves onto it
    a = a.cwiseMax(0.0);
    a /= a.sum();
  }
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int k = 0; k < 4; ++k) c += a[k] * x[ht[k]];

  std::map<std::uint32_t, double> weights;
  for (const auto& [d, t] : near)
    for (const auto node : mesh_.tets()[t]) weights[static_cast<std::uint32_t>(node)] = 0.0;
  const double uniform = 1.0 / static_cast<double>(weights.size());
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  for (const auto& [node, w] : weights) g += uniform * x[node];

  // w = (1 - b) a' + b u reproduces c when a' holds c' = c + s (c - g), s = b / (1 - b).
  // a'(s) = a + s D (c - g) is linear in s: the largest s keeping a' >= 0.
  const Eigen::Vector3d db3 = rest_edge_inverse(hold_tet) * (c - g);
  const Eigen::Vector4d rate(-db3.sum(), db3.x(), db3.y(), db3.z());
  double s = weight_spread / (1.0 - weight_spread);
  for (int k = 0; k < 4; ++k) {
    if (rate[k] < 0.0) s = std::min(s, a[k] / -rate[k]);
  }
  s = std::max(s, 0.0);
  const double b = s / (1.0 + s);
  Eigen::Vector4d a_shift = (a + s * rate).cwiseMax(0.0);  // clamps rounding only
  a_shift /= a_shift.sum();
  for (auto& [node, w] : weights) w = b * uniform;
  for (int k = 0; k < 4; ++k) weights[static_cast<std::uint32_t>(ht[k])] += (1.0 - b) * a_shift[k];

  SphereLink link;
  for (const auto& [d, t] : near) link.tets.push_back(t);
  set_weights(weights, link);
  return link;
}

void TetLinker::set_weights(const std::map<std::uint32_t, double>& weights,
                            SphereLink& link) const {
  double sum = 0.0;
  for (const auto& [node, w] : weights) {
    if (w <= 0.0) continue;
    link.nodes.push_back(node);
    link.weights.push_back(w);
    sum += w;
  }
  const auto& x = mesh_.rest_positions();
  for (double& w : link.weights) w /= sum;
  link.centre_m = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < link.nodes.size(); ++k)
    link.centre_m += link.weights[k] * x[link.nodes[k]];
}

std::int64_t TetLinker::holding_tet(const Eigen::Vector3d& p) {
  candidates(p, p);
  std::int64_t best = -1;
  double best_min = -kInsideTolerance;
  for (const std::uint32_t t : found_) {
    const double m = barycentric(t, p).minCoeff();
    if (m >= best_min) {
      best_min = m;
      best = t;
    }
  }
  return best;
}

SphereLink TetLinker::link_anchored(const Eigen::Vector3d& centre_m, double radius_m,
                                    const Eigen::Vector3d& anchor_m,
                                    const std::array<std::uint32_t, 3>& face_nodes,
                                    const Eigen::Vector3d& face_weights, double depth_factor) {
  SphereLink plain = link(centre_m, radius_m, 0.0);
  const Eigen::Vector3d down = centre_m - anchor_m;
  double k = depth_factor;
  std::int64_t tet = -1;
  for (int attempt = 0; attempt < kAnchorAttempts && k > 1.0 + kMinAnchorShare;
       ++attempt, k = 1.0 + 0.5 * (k - 1.0)) {
    tet = holding_tet(anchor_m + k * down);
    if (tet >= 0) break;
  }
  if (tet < 0) return plain;
  const Eigen::Vector4d inner =
      barycentric(static_cast<std::uint32_t>(tet), anchor_m + k * down).cwiseMax(0.0);
  const double inner_share = 1.0 / k;
  std::map<std::uint32_t, double> weights;
  for (int j = 0; j < 3; ++j)
    weights[face_nodes[static_cast<std::size_t>(j)]] +=
        (1.0 - inner_share) * std::max(0.0, face_weights[j]);
  const auto& ht = mesh_.tets()[static_cast<std::size_t>(tet)];
  for (int j = 0; j < 4; ++j)
    weights[static_cast<std::uint32_t>(ht[j])] += inner_share * inner[j] / inner.sum();
  SphereLink out;
  out.tets = std::move(plain.tets);
  set_weights(weights, out);
  return out;
}

}  // namespace fahr::sphere_layout::detail
