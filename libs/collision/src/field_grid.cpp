// FieldGrid: a single-precision copy of a field's grid (see field_grid.h).
#include "fahr/collision/field_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fahr::collision {

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
        storage_error_m_ =
            std::max(storage_error_m_, std::abs(static_cast<double>(stored) - exact));
      }
    }
  }
}

// locate, distance, distance_gradient and prefetch are inline in the header.

}  // namespace fahr::collision
