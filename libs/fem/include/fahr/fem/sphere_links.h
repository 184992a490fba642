// Immutable map from AIST spheres to FEM nodes: per sphere, node indices and
// weights summing to 1 (the centre is c = sum_i w_i x_i), and a radius.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace fahr::fem {

class SphereLinks {
 public:
  // Weights must be >= 0 and sum to 1 within kWeightSumTolerance; returns an
  // error sentence naming the sphere, or empty on success.
  std::string add_sphere(std::span<const std::uint32_t> nodes, std::span<const double> weights,
                         double radius_m);

  std::size_t size() const { return radius_m_.size(); }
  std::span<const std::uint32_t> nodes(std::size_t sphere) const;
  std::span<const double> weights(std::size_t sphere) const;
  double radius_m(std::size_t sphere) const { return radius_m_[sphere]; }
  // The largest node index referenced, + 1 (0 when empty).
  std::size_t node_bound() const { return node_bound_; }

  // Centre c = sum_i w_i x_i of a sphere, m, for flat positions (3 per node).
  Eigen::Vector3d centre(std::size_t sphere, const double* positions_m) const;

 private:
  std::vector<std::uint32_t> offsets_{0};
  std::vector<std::uint32_t> nodes_;
  std::vector<double> weights_;
  std::vector<double> radius_m_;
  std::size_t node_bound_ = 0;
};

// Barycentric weights are computed in floating point by the haptic side; a
// sum off by more than this is a bug, not rounding.
inline constexpr double kWeightSumTolerance = 1e-6;

}  // namespace fahr::fem
