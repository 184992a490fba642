// A compact copy of a signed distance field's grid for the 1 kHz queries:
// the node values in single precision (half the memory of the field's, so
// more of the tool's neighbourhood stays in cache), a precomputed inverse
// cell, and the trilinear value together with its gradient from the same 8
// corners. The grid narrow phase otherwise reads 7 trilinear values per
// sphere (the centre and central differences); this reads one cell.
// Built once per field (allocates), read-only and allocation-free after.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "fahr/geometry/signed_distance_field.h"

namespace fahr::haptic {

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
  double distance(const Eigen::Vector3d& p) const noexcept;
  // The same value and its gradient (of the trilinear interpolant in p's
  // cell; beyond the grid the direction away from it).
  double distance_gradient(const Eigen::Vector3d& p, Eigen::Vector3d& gradient) const noexcept;

 private:
  // Cell index and fractions of a clamped point; returns the flat index of
  // the cell's lowest corner.
  std::size_t locate(const Eigen::Vector3d& clamped, double f[3]) const noexcept;

  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d top_ = Eigen::Vector3d::Zero();
  double cell_m_ = 0.0;
  double inverse_cell_ = 0.0;
  int nx_ = 0, ny_ = 0, nz_ = 0;
  std::size_t stride_y_ = 0, stride_z_ = 0;
  double storage_error_m_ = 0.0;
  std::vector<float> values_;  // m, x fastest
};

}  // namespace fahr::haptic
