// SphereHash (see sphere_hash.h).
#include "sphere_hash.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fahr::sphere_layout::detail {

SphereHash::SphereHash(std::span<const Eigen::Vector3d> centres_m, std::span<const double> radii_m,
                       double cell_m)
    : centres_(centres_m), radii_(radii_m), cell_m_(cell_m) {
  if (centres_.empty()) {
    start_.assign(2, 0);
    return;
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (std::size_t i = 0; i < centres_.size(); ++i) {
    lo = lo.cwiseMin(centres_[i] - Eigen::Vector3d::Constant(radii_[i]));
    hi = hi.cwiseMax(centres_[i] + Eigen::Vector3d::Constant(radii_[i]));
  }
  origin_ = lo;
  for (int a = 0; a < 3; ++a)
    dims_[a] = std::max(1, static_cast<int>(std::ceil((hi[a] - lo[a]) / cell_m_)) + 1);
  const std::size_t cells = static_cast<std::size_t>(dims_.x()) * dims_.y() * dims_.z();
  std::vector<std::uint32_t> count(cells, 0);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<std::uint32_t> cursor;
    if (pass == 1) {
      start_.assign(cells + 1, 0);
      for (std::size_t c = 0; c < cells; ++c) start_[c + 1] = start_[c] + count[c];
      items_.resize(start_.back());
      cursor.assign(start_.begin(), start_.end() - 1);
    }
    for (std::size_t s = 0; s < centres_.size(); ++s) {
      const Eigen::Vector3i a = cell_of(centres_[s] - Eigen::Vector3d::Constant(radii_[s]));
      const Eigen::Vector3i b = cell_of(centres_[s] + Eigen::Vector3d::Constant(radii_[s]));
      for (int k = a.z(); k <= b.z(); ++k)
        for (int j = a.y(); j <= b.y(); ++j)
          for (int i = a.x(); i <= b.x(); ++i) {
            const std::size_t c = index(i, j, k);
            if (pass == 0) {
              ++count[c];
            } else {
              items_[cursor[c]++] = static_cast<std::uint32_t>(s);
            }
          }
    }
  }
}

Eigen::Vector3i SphereHash::cell_of(const Eigen::Vector3d& p) const {
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) {
    c[a] = std::clamp(static_cast<int>(std::floor((p[a] - origin_[a]) / cell_m_)), 0, dims_[a] - 1);
  }
  return c;
}

bool SphereHash::covered_by_other(const Eigen::Vector3d& p, std::uint32_t self,
                                  double slack_m) const {
  if (centres_.empty()) return false;
  const Eigen::Vector3i c = cell_of(p);
  const std::size_t cell = index(c.x(), c.y(), c.z());
  for (std::uint32_t e = start_[cell]; e < start_[cell + 1]; ++e) {
    const std::uint32_t s = items_[e];
    if (s == self) continue;
    if ((p - centres_[s]).norm() < radii_[s] - slack_m) return true;
  }
  return false;
}

double SphereHash::distance_to_union(const Eigen::Vector3d& p, double reach_m) const {
  double best = std::numeric_limits<double>::infinity();
  if (centres_.empty()) return best;
  const Eigen::Vector3i a = cell_of(p - Eigen::Vector3d::Constant(reach_m));
  const Eigen::Vector3i b = cell_of(p + Eigen::Vector3d::Constant(reach_m));
  for (int k = a.z(); k <= b.z(); ++k)
    for (int j = a.y(); j <= b.y(); ++j)
      for (int i = a.x(); i <= b.x(); ++i) {
        const std::size_t cell = index(i, j, k);
        for (std::uint32_t e = start_[cell]; e < start_[cell + 1]; ++e) {
          const std::uint32_t s = items_[e];
          best = std::min(best, (p - centres_[s]).norm() - radii_[s]);
        }
      }
  return best;
}

double SphereHash::distance_to_union_brute_force(const Eigen::Vector3d& p) const {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t s = 0; s < centres_.size(); ++s)
    best = std::min(best, (p - centres_[s]).norm() - radii_[s]);
  return best;
}

}  // namespace fahr::sphere_layout::detail
