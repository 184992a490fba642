// A compact copy of a signed distance field's grid for the 1 kHz queries:
// the node values in single precision (half the memory of the field's, so
// more of the tool's neighbourhood stays in cache), a precomputed inverse
// cell, and the trilinear value together with its gradient from the same 8
// corners. The grid narrow phase otherwise reads 7 trilinear values per
// sphere (the centre and central differences); this reads one cell.
// Built once per field (allocates), read-only and allocation-free after.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "fahr/geometry/signed_distance_field.h"

namespace fahr::collision {

class FieldGrid {
 public:
  FieldGrid() = default;
  // Copies the field's grid (its trilinear value at every node).
  explicit FieldGrid(const geometry::SignedDistanceField& sdf);

  bool empty() const { return values_.empty(); }
  double cell_size_m() const { return cell_m_; }
  // Largest |stored - field| over the nodes, m: the rounding of the copy, to
  // be added to any error bound that holds for the field's grid.
  double storage_error_m() const { return storage_error_m_; }

  // The trilinear value, m, as SignedDistanceField::grid_distance (beyond the
  // grid: the value at the nearest grid point plus the distance to it). NaN
  // for a non-finite p; +inf when empty.
  // Inline (here, not in the .cpp): the query reads it once per tree node
  // and sphere, and a call per read cost ~15 % of the query (perf, aist_bench
  // replay).
  double distance(const Eigen::Vector3d& p) const noexcept;
  // The same value and its gradient (of the trilinear interpolant in p's
  // cell; beyond the grid the direction away from it).
  double distance_gradient(const Eigen::Vector3d& p, Eigen::Vector3d& gradient) const noexcept;
  // The value now and the gradient only if asked (the same numbers as
  // distance_gradient): the query tests most spheres by the value alone.
  struct Read {
    double value = 0.0;
    // The cell's corners and p's fractions in it, for gradient().
    double v000 = 0.0, v100 = 0.0, v010 = 0.0, v110 = 0.0, v001 = 0.0, v101 = 0.0, v011 = 0.0,
           v111 = 0.0;
    double c00 = 0.0, c10 = 0.0, c01 = 0.0, c11 = 0.0, c0 = 0.0, c1 = 0.0;
    double f[3] = {0.0, 0.0, 0.0};
    Eigen::Vector3d outside = Eigen::Vector3d::Zero();  // p less its clamp to the grid
    double beyond = 0.0;                                // |outside|
    bool cell = false;                                  // false: NaN p or an empty grid
  };
  Read read(const Eigen::Vector3d& p) const noexcept;
  Eigen::Vector3d gradient(const Read& r) const noexcept;
  // Asks the cache for the lines a read at p will touch (changes no value):
  // when the grid is cold (the haptic tick after a FEM step) a leaf's reads
  // then overlap instead of waiting on memory one after another.
  void prefetch(const Eigen::Vector3d& p) const noexcept;

 private:
  // Cell index and fractions of a clamped point; returns the flat index of
  // the cell's lowest corner.
  std::size_t locate(const Eigen::Vector3d& clamped, double f[3]) const noexcept;
  // |p - clamped| without a square root inside the grid (the common case);
  // the same value bit for bit, 0 there.
  static double beyond(const Eigen::Vector3d& p, const Eigen::Vector3d& clamped) noexcept {
    const double squared = (p - clamped).squaredNorm();
    return squared > 0.0 ? std::sqrt(squared) : 0.0;
  }

  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d top_ = Eigen::Vector3d::Zero();
  double cell_m_ = 0.0;
  double inverse_cell_ = 0.0;
  int nx_ = 0, ny_ = 0, nz_ = 0;
  std::size_t stride_y_ = 0, stride_z_ = 0;
  double storage_error_m_ = 0.0;
  std::vector<float> values_;  // m, x fastest
};

inline std::size_t FieldGrid::locate(const Eigen::Vector3d& clamped, double f[3]) const noexcept {
  const Eigen::Vector3d u = (clamped - origin_) * inverse_cell_;
  // u >= 0 after the clamp, so truncation is the floor; the top face belongs
  // to the last cell.
  const int i = std::min(static_cast<int>(u.x()), nx_ - 2);
  const int j = std::min(static_cast<int>(u.y()), ny_ - 2);
  const int k = std::min(static_cast<int>(u.z()), nz_ - 2);
  f[0] = u.x() - i;
  f[1] = u.y() - j;
  f[2] = u.z() - k;
  return static_cast<std::size_t>(i) + stride_y_ * static_cast<std::size_t>(j) +
         stride_z_ * static_cast<std::size_t>(k);
}

inline double FieldGrid::distance(const Eigen::Vector3d& p) const noexcept {
  if (!p.allFinite())
    return std::numeric_limits<double>::quiet_NaN();  // a NaN pose must not index the grid
  if (values_.empty()) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d clamped = p.cwiseMax(origin_).cwiseMin(top_);
  double f[3];
  const float* v = values_.data() + locate(clamped, f);
  const float* w = v + stride_z_;
  // Along x on the four edges, then y, then z.
  const double c00 = v[0] + f[0] * (v[1] - v[0]);
  const double c10 = v[stride_y_] + f[0] * (v[stride_y_ + 1] - v[stride_y_]);
  const double c01 = w[0] + f[0] * (w[1] - w[0]);
  const double c11 = w[stride_y_] + f[0] * (w[stride_y_ + 1] - w[stride_y_]);
  const double c0 = c00 + f[1] * (c10 - c00);
  const double c1 = c01 + f[1] * (c11 - c01);
  return c0 + f[2] * (c1 - c0) + beyond(p, clamped);
}

inline double FieldGrid::distance_gradient(const Eigen::Vector3d& p,
                                           Eigen::Vector3d& gradient) const noexcept {
  gradient = Eigen::Vector3d::UnitZ();
  if (!p.allFinite()) return std::numeric_limits<double>::quiet_NaN();
  if (values_.empty()) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d clamped = p.cwiseMax(origin_).cwiseMin(top_);
  double f[3];
  const float* v = values_.data() + locate(clamped, f);
  const float* w = v + stride_z_;
  const double v000 = v[0], v100 = v[1], v010 = v[stride_y_], v110 = v[stride_y_ + 1];
  const double v001 = w[0], v101 = w[1], v011 = w[stride_y_], v111 = w[stride_y_ + 1];
  const double c00 = v000 + f[0] * (v100 - v000);
  const double c10 = v010 + f[0] * (v110 - v010);
  const double c01 = v001 + f[0] * (v101 - v001);
  const double c11 = v011 + f[0] * (v111 - v011);
  const double c0 = c00 + f[1] * (c10 - c00);
  const double c1 = c01 + f[1] * (c11 - c01);
  const double outside = beyond(p, clamped);
  if (outside > 0.0) {
    gradient = (p - clamped) / outside;
  } else {
    // d/dx: the x differences of the four edges, interpolated in y and z.
    const double dx0 = (v100 - v000) + f[1] * ((v110 - v010) - (v100 - v000));
    const double dx1 = (v101 - v001) + f[1] * ((v111 - v011) - (v101 - v001));
    gradient.x() = (dx0 + f[2] * (dx1 - dx0)) * inverse_cell_;
    gradient.y() = ((c10 - c00) + f[2] * ((c11 - c01) - (c10 - c00))) * inverse_cell_;
    gradient.z() = (c1 - c0) * inverse_cell_;
  }
  return c0 + f[2] * (c1 - c0) + outside;
}

inline FieldGrid::Read FieldGrid::read(const Eigen::Vector3d& p) const noexcept {
  Read r;
  if (!p.allFinite()) {
    r.value = std::numeric_limits<double>::quiet_NaN();
    return r;
  }
  if (values_.empty()) {
    r.value = std::numeric_limits<double>::infinity();
    return r;
  }
  r.cell = true;
  const Eigen::Vector3d clamped = p.cwiseMax(origin_).cwiseMin(top_);
  const float* v = values_.data() + locate(clamped, r.f);
  const float* w = v + stride_z_;
  // As distance_gradient, term for term (the same rounding).
  r.v000 = v[0], r.v100 = v[1], r.v010 = v[stride_y_], r.v110 = v[stride_y_ + 1];
  r.v001 = w[0], r.v101 = w[1], r.v011 = w[stride_y_], r.v111 = w[stride_y_ + 1];
  r.c00 = r.v000 + r.f[0] * (r.v100 - r.v000);
  r.c10 = r.v010 + r.f[0] * (r.v110 - r.v010);
  r.c01 = r.v001 + r.f[0] * (r.v101 - r.v001);
  r.c11 = r.v011 + r.f[0] * (r.v111 - r.v011);
  r.c0 = r.c00 + r.f[1] * (r.c10 - r.c00);
  r.c1 = r.c01 + r.f[1] * (r.c11 - r.c01);
  r.outside = p - clamped;
  r.beyond = beyond(p, clamped);
  r.value = r.c0 + r.f[2] * (r.c1 - r.c0) + r.beyond;
  return r;
}

inline void FieldGrid::prefetch(const Eigen::Vector3d& p) const noexcept {
  if (!p.allFinite() || values_.empty()) return;
  double f[3];
  const float* v = values_.data() + locate(p.cwiseMax(origin_).cwiseMin(top_), f);
  // The cell's four x-edges (each two floats, one line unless it straddles one).
  __builtin_prefetch(v);
  __builtin_prefetch(v + stride_y_);
  __builtin_prefetch(v + stride_z_);
  __builtin_prefetch(v + stride_z_ + stride_y_);
}

inline Eigen::Vector3d FieldGrid::gradient(const Read& r) const noexcept {
  if (!r.cell) return Eigen::Vector3d::UnitZ();
  if (r.beyond > 0.0) return r.outside / r.beyond;
  const double dx0 = (r.v100 - r.v000) + r.f[1] * ((r.v110 - r.v010) - (r.v100 - r.v000));
  const double dx1 = (r.v101 - r.v001) + r.f[1] * ((r.v111 - r.v011) - (r.v101 - r.v001));
  return Eigen::Vector3d(
      (dx0 + r.f[2] * (dx1 - dx0)) * inverse_cell_,
      ((r.c10 - r.c00) + r.f[2] * ((r.c11 - r.c01) - (r.c10 - r.c00))) * inverse_cell_,
      (r.c1 - r.c0) * inverse_cell_);
}

}  // namespace fahr::collision
