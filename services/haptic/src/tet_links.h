// Ties a sphere to the tets it overlaps and gives its node weights
// (DESIGN.md, "Sphere to tissue"), internal.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "fahr/geometry/tet_mesh.h"

namespace fahr::haptic::detail {

struct SphereLink {
  std::vector<std::uint32_t> tets;     // nearest first, ties by index
  std::vector<std::uint32_t> nodes;    // ascending
  std::vector<double> weights;         // >= 0, sum 1, sum w x_rest = centre
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();  // = sum w x_rest, m
};

// Uniform grid over the tets' boxes: finds the tets near a sphere without a
// search over all of them. Built once per filling.
class TetLinker {
 public:
  explicit TetLinker(const geometry::TetMesh& mesh, int max_linked_tets);

  // The up-to-max_linked_tets tets nearest the centre among those the sphere
  // overlaps (the tet holding the centre first), and weights: the
  // barycentric weights a of a point c' in the holding tet blended with the
  // uniform weights u over all linked nodes, w = (1 - b) a + b u, where c'
  // is chosen so that w reproduces the centre exactly and b is the largest
  // share up to weight_spread that keeps c' inside the tet (so w >= 0).
  SphereLink link(const Eigen::Vector3d& centre_m, double radius_m, double weight_spread);

 private:
  Eigen::Vector4d barycentric(std::uint32_t tet, const Eigen::Vector3d& p) const;
  double distance_to_tet(std::uint32_t tet, const Eigen::Vector3d& p) const;
  void candidates(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi);

  const geometry::TetMesh& mesh_;
  int max_linked_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  double cell_m_ = 1.0;
  Eigen::Vector3i dims_ = Eigen::Vector3i::Ones();
  std::vector<std::uint32_t> cell_start_;
  std::vector<std::uint32_t> cell_tets_;
  std::vector<std::uint32_t> stamp_;
  std::uint32_t current_stamp_ = 0;
  std::vector<std::uint32_t> found_;
};

}  // namespace fahr::haptic::detail
