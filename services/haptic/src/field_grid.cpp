// FieldGrid: a single-precision copy of a field's grid (see field_grid.h).
#include "fahr/haptic/field_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fahr::haptic {

FieldGrid::FieldGrid(const geometry::SignedDistanceField& sdf) {
  const Eigen::Vector3i dims = sdf.grid_dimensions();
  if (dims.minCoeff() < 2) return;
  origin_ = sdf.grid_origin_m();
  cell_m_ = sdf.cell_size_m();
  inverse_cell_ = 1.0 / cell_m_;
  nx_ = dims.x();
  ny_ = dims.y();
  nz_ = dims.z();
  top_ = origin_ + cell_m_ * (dims - Eigen::Vector3i::Ones()).cast<double>();
  stride_y_ = static_cast<std::size_t>(nx_);
  stride_z_ = stride_y_ * static_cast<std::size_t>(ny_);
  values_.resize(stride_z_ * static_cast<std::size_t>(nz_));
  // The field keeps its node values private; its trilinear value at a node
  // is that node's value (to a rounding of the node's coordinates).
  for (int k = 0; k < nz_; ++k) {
    for (int j = 0; j < ny_; ++j) {
      for (int i = 0; i < nx_; ++i) {
        const Eigen::Vector3d p = origin_ + cell_m_ * Eigen::Vector3d(i, j, k);
        const double exact = sdf.grid_distance(p.cwiseMin(top_));
        const auto stored = static_cast<float>(exact);
        values_[static_cast<std::size_t>(i) + stride_y_ * static_cast<std::size_t>(j) +
                stride_z_ * static_cast<std::size_t>(k)] = stored;
        storage_error_m_ = std::max(storage_error_m_, std::abs(static_cast<double>(stored) - exact));
      }
    }
  }
}

std::size_t FieldGrid::locate(const Eigen::Vector3d& clamped, double f[3]) const noexcept {
  const Eigen::Vector3d u = (clamped - origin_) * inverse_cell_;
  // u >= 0 after the clamp, so truncation is the floor; the top face belongs
  // to the last cell.
  const int i = std::min(static_cast<int>(u.x()), nx_ - 2);
  const int j = std::min(static_cast<int>(u.y()), ny_ - 2);
  const int k = std::min(static_cast<int>(u.z()), nz_ - 2);
  f[0] = u.x() - i;
  f[1] = u.y() - j;
  f[2] = u.z() - k;
  return static_cast<std::size_t>(i) + stride_y_ * static_cast<std::size_t>(j) + stride_z_ * static_cast<std::size_t>(k);
}

double FieldGrid::distance(const Eigen::Vector3d& p) const noexcept {
  if (!p.allFinite()) return std::numeric_limits<double>::quiet_NaN();  // a NaN pose must not index the grid
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
  return c0 + f[2] * (c1 - c0) + (p - clamped).norm();
}

double FieldGrid::distance_gradient(const Eigen::Vector3d& p, Eigen::Vector3d& gradient) const noexcept {
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
  const Eigen::Vector3d outside = p - clamped;
  const double beyond = outside.norm();
  if (beyond > 0.0) {
    gradient = outside / beyond;
  } else {
    // d/dx: the x differences of the four edges, interpolated in y and z.
    const double dx0 = (v100 - v000) + f[1] * ((v110 - v010) - (v100 - v000));
    const double dx1 = (v101 - v001) + f[1] * ((v111 - v011) - (v101 - v001));
    gradient.x() = (dx0 + f[2] * (dx1 - dx0)) * inverse_cell_;
    gradient.y() = ((c10 - c00) + f[2] * ((c11 - c01) - (c10 - c00))) * inverse_cell_;
    gradient.z() = (c1 - c0) * inverse_cell_;
  }
  return c0 + f[2] * (c1 - c0) + beyond;
}

}  // namespace fahr::haptic
