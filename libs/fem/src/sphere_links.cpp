// Flat (CSR-like) storage of sphere-to-node weights.
#include "fahr/fem/sphere_links.h"

#include <algorithm>
#include <cmath>

namespace fahr::fem {

std::string SphereLinks::add_sphere(std::span<const std::uint32_t> nodes,
                                    std::span<const double> weights, double radius_m) {
  const std::string name = "sphere " + std::to_string(size());
  if (nodes.empty() || nodes.size() != weights.size())
    return name + ": needs as many weights as nodes (> 0)";
  if (!(radius_m >= 0.0) || !std::isfinite(radius_m))
    return name + ": radius_m must be finite and >= 0";
  double sum = 0.0;
  for (const double w : weights) {
    if (!(w >= 0.0) || !std::isfinite(w)) return name + ": weights must be finite and >= 0";
    sum += w;
  }
  if (std::abs(sum - 1.0) > kWeightSumTolerance)
    return name + ": weights sum to " + std::to_string(sum);
  nodes_.insert(nodes_.end(), nodes.begin(), nodes.end());
  weights_.insert(weights_.end(), weights.begin(), weights.end());
  offsets_.push_back(static_cast<std::uint32_t>(nodes_.size()));
  radius_m_.push_back(radius_m);
  for (const std::uint32_t node : nodes)
    node_bound_ = std::max<std::size_t>(node_bound_, node + std::size_t{1});
  return {};
}

std::span<const std::uint32_t> SphereLinks::nodes(std::size_t sphere) const {
  return {nodes_.data() + offsets_[sphere], offsets_[sphere + 1] - offsets_[sphere]};
}

std::span<const double> SphereLinks::weights(std::size_t sphere) const {
  return {weights_.data() + offsets_[sphere], offsets_[sphere + 1] - offsets_[sphere]};
}

Eigen::Vector3d SphereLinks::centre(std::size_t sphere, const double* positions_m) const {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  const auto n = nodes(sphere);
  const auto w = weights(sphere);
  for (std::size_t k = 0; k < n.size(); ++k) {
    c += w[k] * Eigen::Map<const Eigen::Vector3d>(positions_m + 3 * std::size_t{n[k]});
  }
  return c;
}

}  // namespace fahr::fem
