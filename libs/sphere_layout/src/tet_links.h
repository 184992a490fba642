// Ties a sphere to the tets it overlaps and gives its node weights
// (docs/design/contact-contract.md, sphere to tissue), internal.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include "fahr/geometry/tet_mesh.h"

namespace fahr::sphere_layout::detail {

struct SphereLink {
  std::vector<std::uint32_t> tets;                     // nearest first, ties by index
  std::vector<std::uint32_t> nodes;                    // ascending
  std::vector<double> weights;                         // >= 0, sum 1, sum w x_rest = centre
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

  // A sphere that stands for the surface near `anchor_m` (a point of a
  // boundary face with nodes face_nodes and barycentric face_weights): the
  // centre is written as the point 1/depth_factor of the way from the anchor
  // to p = anchor + depth_factor (centre - anchor), so the face's nodes carry
  // 1 - 1/depth_factor of the weight and p's holding tet the rest. The FEM
  // then moves the surface itself when it projects the sphere, and the sphere
  // follows the surface when it deforms. The factor is lowered toward 1 when
  // p would leave the mesh; at 1 (or if no tet holds p) this is link() with
  // no spread. Tets (for the radius) are link()'s.
  SphereLink link_anchored(const Eigen::Vector3d& centre_m, double radius_m,
                           const Eigen::Vector3d& anchor_m,
                           const std::array<std::uint32_t, 3>& face_nodes,
                           const Eigen::Vector3d& face_weights, double depth_factor);

 private:
  // Dm^-1 of a tet at rest, computed when asked (set-up only; the mesh keeps none).
  Eigen::Matrix3d rest_edge_inverse(std::uint32_t tet) const;
  Eigen::Vector4d barycentric(std::uint32_t tet, const Eigen::Vector3d& p) const;
  double distance_to_tet(std::uint32_t tet, const Eigen::Vector3d& p) const;
  // The positive weights (normalised to sum 1), their nodes and the centre they give at rest.
  void set_weights(const std::map<std::uint32_t, double>& weights, SphereLink& link) const;
  // The tet holding p with the largest smallest barycentric coordinate, or -1.
  std::int64_t holding_tet(const Eigen::Vector3d& p);
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

}  // namespace fahr::sphere_layout::detail
