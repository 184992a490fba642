// The immutable part of an adaptive inner sphere tree: rest centres, rest
// radii, refinement level and, per sphere, the tets it is tied to and the
// node weights that carry its centre (docs/design/contact-contract.md, sphere to tissue):
//   c = sum_i w_i x_i,  w_i >= 0,  sum_i w_i = 1.
// Built once from a tet mesh (fill_spheres), shared read-only by every state.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "fahr/geometry/tet_mesh.h"

namespace fahr::sphere_layout {

// Where a sphere comes from.
enum class SphereOrigin : std::uint8_t {
  kGrid,     // a grid or octree cell (its level says which)
  kHugging,  // a surface-hugging sphere of the coverage closure
};

struct SphereRecord {
  Eigen::Vector3d rest_centre_m = Eigen::Vector3d::Zero();  // m, = sum w_i x_i at rest
  double rest_radius_m = 0.0;                               // m, > 0
  double rest_linked_volume_m3 = 0.0;                       // rest volume of the linked tets, m^3
  std::uint32_t first_link = 0;                             // into link_nodes / link_weights
  std::uint32_t link_count = 0;
  std::uint32_t first_tet = 0;  // into linked_tets
  std::uint32_t tet_count = 0;
  std::uint8_t level = 0;  // 0 = coarse grid, refinement_levels = finest
  SphereOrigin origin = SphereOrigin::kGrid;
};

// A sphere's point on the body's boundary (ours): the nearest boundary point
// of its rest centre, written as barycentric weights of that boundary face's
// three nodes, so it moves with the deformed surface. The sphere detects (its
// union is cheap to test and to prune), the surface measures: a sphere
// reports, beside its own depth, the penetration of its anchor
// (SphereContact::surface_depth_m). The volume-preserving radius rule keeps
// spheres at their rest radius while the tissue under a blade is squashed,
// so they stand out of the deformed surface; the anchor lies on it.
struct SurfaceAnchor {
  std::array<std::uint32_t, 3> nodes{};                    // the face's nodes
  std::array<double, 3> weights{};                         // >= 0, sum 1
  Eigen::Vector3d rest_point_m = Eigen::Vector3d::Zero();  // = sum w_i x_i at rest, m
  std::array<Eigen::Vector3d, 3> rest_face_m{};            // the nodes at rest, m
};

class SphereLayout {
 public:
  SphereLayout() = default;
  // Assembled by fill_spheres; checks that weights are >= 0 and sum to 1 and
  // throws std::invalid_argument otherwise (a bug, not bad input).
  SphereLayout(std::vector<SphereRecord> spheres, std::vector<std::uint32_t> link_nodes,
               std::vector<double> link_weights, std::vector<std::uint32_t> linked_tets,
               std::vector<geometry::Tet> tets, std::size_t node_count, int finest_level,
               double coarse_radius_m);
  // Anchors: one slot per sphere; has_anchor[i] == 0 marks a sphere without
  // one (too far from the boundary, FillSettings::anchor_gap_m). Checked as
  // the links are; both empty: no sphere has an anchor.
  void set_anchors(std::vector<SurfaceAnchor> anchors, std::vector<std::uint8_t> has_anchor);

  std::size_t size() const { return spheres_.size(); }
  const SphereRecord& sphere(std::size_t i) const { return spheres_[i]; }
  const std::vector<SphereRecord>& spheres() const { return spheres_; }
  std::span<const std::uint32_t> nodes(std::size_t i) const {
    return {link_nodes_.data() + spheres_[i].first_link, spheres_[i].link_count};
  }
  std::span<const double> weights(std::size_t i) const {
    return {link_weights_.data() + spheres_[i].first_link, spheres_[i].link_count};
  }
  std::span<const std::uint32_t> tets_of(std::size_t i) const {
    return {linked_tets_.data() + spheres_[i].first_tet, spheres_[i].tet_count};
  }
  const std::vector<geometry::Tet>& tets() const { return tets_; }
  // The sphere's surface anchor, or null when it has none.
  const SurfaceAnchor* anchor(std::size_t i) const {
    return i < has_anchor_.size() && has_anchor_[i] != 0 ? &anchors_[i] : nullptr;
  }
  std::size_t anchor_count() const;
  std::size_t node_count() const { return node_count_; }
  int finest_level() const { return finest_level_; }
  double coarse_radius_m() const { return coarse_radius_m_; }  // level-0 radius, m
  std::size_t count(SphereOrigin origin) const;
  std::size_t count_at_level(int level) const;  // grid spheres of one level

  // 64-bit FNV-1a over every stored byte: equal layouts give equal hashes, so
  // a test can prove that the filling is deterministic.
  std::uint64_t fingerprint() const;

 private:
  std::vector<SphereRecord> spheres_;
  std::vector<std::uint32_t> link_nodes_;
  std::vector<double> link_weights_;
  std::vector<std::uint32_t> linked_tets_;
  std::vector<geometry::Tet> tets_;       // the mesh's tets, for the volume of the linked ones
  std::vector<SurfaceAnchor> anchors_;    // per sphere, or empty
  std::vector<std::uint8_t> has_anchor_;  // per sphere, or empty
  std::size_t node_count_ = 0;
  int finest_level_ = 0;
  double coarse_radius_m_ = 0.0;
};

// The layouts of several bodies as one, for a service that queries them as
// one tissue (several deformable bodies, docs/design/two-deformable-bodies.md):
// the spheres of layouts[b] follow those of the layouts before it, and their
// node and tet indices are shifted by node_offsets[b] and by the tets before
// it (node_offsets[b]: the nodes of the bodies before b, in the same order
// as the union mesh's). One layout gives an equal copy. Throws
// std::invalid_argument when the sizes disagree.
SphereLayout concatenate(std::span<const SphereLayout* const> layouts,
                         std::span<const std::size_t> node_offsets);

// Weights that sum to 1 within this are accepted: they are formed in double
// precision from a handful of terms, so a larger error is a bug.
inline constexpr double kWeightSumTolerance = 1e-9;

}  // namespace fahr::sphere_layout
