// Bounding hierarchy over the spheres, separate from the spheres themselves
// (an inner sphere does not bound its children): a binary tree of axis-aligned
// boxes built once on the rest layout and refitted bottom-up for every FEM
// state. The topology never changes, so the structure is never rebuilt; a
// counter lets tests prove it.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

#include "fahr/collision/sphere_state.h"
#include "fahr/sphere_layout/sphere_layout.h"

namespace fahr::collision {

struct SphereTreeNode {
  Eigen::Vector3d box_min_m = Eigen::Vector3d::Zero();  // m
  Eigen::Vector3d box_max_m = Eigen::Vector3d::Zero();  // m
  // Leaf: first sphere slot in order() and the count; inner: left child index
  // (right = left + 1) and count 0. Children always follow their parent, so a
  // reverse sweep refits bottom-up.
  std::int32_t first = 0;
  std::int32_t count = 0;
  // Radius of a ball about the box's middle that holds every sphere of the
  // node, m (<= the box's half diagonal, tighter for round clusters): the
  // queries' bound on how near the body a sphere of the node can reach.
  double reach_m = 0.0;
};

class SphereTree {
 public:
  // Spheres per leaf. 16 rather than 4: the query's cost per tree node (a
  // grid read at the box's middle, a bound, a push) exceeds its cost per
  // sphere tested, so fewer, larger leaves were faster though they test more
  // spheres (aist_bench replay: grid query warm p99.9 -10 % at 8, -12 % at
  // 16; docs/design/aist-layout.md).
  static constexpr int kLeafSize = 16;
  // Within a leaf the spheres are in the order the former tree of 4-sphere
  // leaves visited them (its median splits, right half first), so the query
  // reports contacts in the same order as before: the FEM's projection
  // takes them in that order and is not order-free.
  static constexpr int kBlockSize = 4;
  static constexpr int kMaxDepth = 64;  // traversal stack; median splits keep depth ~log2(n/16)+1

  SphereTree() = default;
  explicit SphereTree(const sphere_layout::SphereLayout& layout);

  // Boxes of every node from the state's centres and radii. Allocation-free.
  void refit(const SphereState& state);

  const std::vector<SphereTreeNode>& nodes() const { return nodes_; }
  const std::vector<std::uint32_t>& order() const { return order_; }  // sphere ids, leaf order
  // The last refit's centre (x, y, z) and radius per slot of order(), m: the
  // query reads spheres leaf by leaf, so a copy in that order is read
  // sequentially where the state's arrays (by sphere id) are read at random.
  const std::vector<Eigen::Vector4d>& slot_spheres() const { return slot_spheres_; }
  // The last refit's surface anchor per slot (SphereState::anchors_m, NaN
  // for none), m, in the same order: the query reads it for the spheres it
  // reports, next to their centres.
  const std::vector<Eigen::Vector3d>& slot_anchors() const { return slot_anchors_; }
  // Likewise the anchor's deformed face (SphereState::anchor_faces_m).
  const std::vector<std::array<Eigen::Vector3d, 3>>& slot_faces() const { return slot_faces_; }
  int depth() const { return depth_; }
  std::uint64_t refit_count() const { return refits_; }
  // Builds after construction. Nothing in the library rebuilds, so this stays 0.
  std::uint64_t rebuild_count() const { return builds_ - 1; }

 private:
  void build(std::int32_t node, std::int32_t begin, std::int32_t end, int depth,
             const sphere_layout::SphereLayout& layout);
  // Median split of order_[begin, end) on its widest axis; returns the middle.
  std::int32_t split(std::int32_t begin, std::int32_t end,
                     const sphere_layout::SphereLayout& layout);
  // Appends order_[begin, end) to out in the walk order of kBlockSize leaves.
  void arrange_leaf(std::int32_t begin, std::int32_t end, const sphere_layout::SphereLayout& layout,
                    std::vector<std::uint32_t>& out);

  std::vector<SphereTreeNode> nodes_;
  std::vector<std::uint32_t> order_;
  std::vector<Eigen::Vector4d> slot_spheres_;
  bool anchored_ = false;  // the layout has surface anchors to copy
  std::vector<Eigen::Vector3d> slot_anchors_;
  std::vector<std::array<Eigen::Vector3d, 3>> slot_faces_;
  int depth_ = 0;
  std::uint64_t builds_ = 1;
  std::uint64_t refits_ = 0;
};

}  // namespace fahr::collision
