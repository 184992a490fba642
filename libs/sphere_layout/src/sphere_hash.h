// Uniform grid over spheres (internal): every sphere is listed in each cell
// its box touches, so "is p inside another sphere" reads one cell and "how
// far is p from the union" reads the cells of a box around p.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

namespace fahr::sphere_layout::detail {

class SphereHash {
 public:
  SphereHash(std::span<const Eigen::Vector3d> centres_m, std::span<const double> radii_m,
             double cell_m);

  // True if p lies strictly inside a sphere other than `self` by more than `slack_m`.
  bool covered_by_other(const Eigen::Vector3d& p, std::uint32_t self, double slack_m) const;
  // min_i (|p - c_i| - r_i) over spheres in the cells within reach_m of p;
  // +infinity if none is there.
  double distance_to_union(const Eigen::Vector3d& p, double reach_m) const;
  // The same over every sphere (the fallback when nothing is within reach).
  double distance_to_union_brute_force(const Eigen::Vector3d& p) const;

 private:
  Eigen::Vector3i cell_of(const Eigen::Vector3d& p) const;
  std::size_t index(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(dims_.x()) *
               (static_cast<std::size_t>(j) +
                static_cast<std::size_t>(dims_.y()) * static_cast<std::size_t>(k));
  }

  std::span<const Eigen::Vector3d> centres_;
  std::span<const double> radii_;
  double cell_m_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  Eigen::Vector3i dims_ = Eigen::Vector3i::Ones();
  std::vector<std::uint32_t> start_;
  std::vector<std::uint32_t> items_;
};

}  // namespace fahr::sphere_layout::detail
