// Per-node rotation of a lagged factorisation.
#include "fahr/fem/warped_factor.h"

#include <algorithm>

#include "fahr/fem/corotation.h"

namespace fahr::fem {

void WarpedFactor::resize(std::size_t node_count) {
  sums_.assign(node_count, Eigen::Matrix3d::Zero());
  current_.assign(node_count, Eigen::Matrix3d::Identity());
  at_factor_.assign(node_count, Eigen::Matrix3d::Identity());
  delta_.assign(node_count, Eigen::Matrix3d::Identity());
  scratch_.setZero(
      static_cast<Eigen::Index>(3 * node_count));  // one column: solves rotate column by column
}

void WarpedFactor::update_rotations(const ElementRest& rest,
                                    std::span<const Eigen::Matrix3d> element_rotations) {
  if (!enabled_) return;
  for (Eigen::Matrix3d& sum : sums_) sum.setZero();
  for (std::size_t e = 0; e < rest.size(); ++e) {
    // Volume weights: a sliver's rotation is ill-conditioned (its F
    // amplifies node noise by 1/thickness) and must not steer its nodes.
    const Eigen::Matrix3d weighted = rest.volume_m3[e] * element_rotations[e];
    for (const std::uint32_t node : rest.tets[e]) sums_[node] += weighted;
  }
  for (std::size_t i = 0; i < sums_.size(); ++i) {
    // A node in no element keeps its rotation (the sum is zero).
    if (sums_[i].squaredNorm() > 0.0) current_[i] = rotation_from_deformation(sums_[i]).rotation;
    delta_[i] = current_[i] * at_factor_[i].transpose();
  }
}

void WarpedFactor::mark_factorised() {
  at_factor_ = current_;  // same size: no allocation
  for (Eigen::Matrix3d& q : delta_) q.setIdentity();
}

void WarpedFactor::rotate_to_factor_frame(const double* in, double* out) const {
  for (std::size_t i = 0; i < delta_.size(); ++i) {
    Eigen::Map<Eigen::Vector3d>(out + 3 * i) =
        delta_[i].transpose() * Eigen::Map<const Eigen::Vector3d>(in + 3 * i);
  }
}

void WarpedFactor::rotate_to_current_frame(const double* in, double* out) const {
  for (std::size_t i = 0; i < delta_.size(); ++i) {
    Eigen::Map<Eigen::Vector3d>(out + 3 * i) =
        delta_[i] * Eigen::Map<const Eigen::Vector3d>(in + 3 * i);
  }
}

void WarpedFactor::solve(CholmodSolver& factor, const double* b, double* x) {
  const std::size_t n = 3 * delta_.size();
  if (!enabled_) {
    factor.solve({b, n}, {x, n});
    return;
  }
  rotate_to_factor_frame(b, scratch_.data());
  factor.solve({scratch_.data(), n}, {x, n});
  std::copy(x, x + n, scratch_.data());
  rotate_to_current_frame(scratch_.data(), x);
}

void WarpedFactor::solve_columns(CholmodSolver& factor, std::span<double> b, std::span<double> x,
                                 int columns) {
  const std::size_t n = 3 * delta_.size();
  const auto count = static_cast<std::size_t>(columns);
  if (enabled_) {
    for (std::size_t c = 0; c < count; ++c) {
      rotate_to_factor_frame(b.data() + c * n, scratch_.data());
      std::copy(scratch_.data(), scratch_.data() + n, b.data() + c * n);
    }
  }
  factor.solve_columns(b, x, columns);
  if (enabled_) {
    for (std::size_t c = 0; c < count; ++c) {
      rotate_to_current_frame(x.data() + c * n, scratch_.data());
      std::copy(scratch_.data(), scratch_.data() + n, x.data() + c * n);
    }
  }
}

}  // namespace fahr::fem
