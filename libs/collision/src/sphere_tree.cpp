// SphereTree: median-split build on the rest layout, once; refit per state.
#include "fahr/collision/sphere_tree.h"

#include <algorithm>
#include <limits>
#include <numeric>

namespace fahr::collision {

SphereTree::SphereTree(const sphere_layout::SphereLayout& layout) {
  const auto n = static_cast<std::int32_t>(layout.size());
  order_ = std::vector<std::uint32_t>(layout.size(), 0U);
  std::iota(order_.begin(), order_.end(), 0U);
  // A binary tree over n leaves of up to kLeafSize has fewer than 2n nodes.
  nodes_.reserve(2 * layout.size() + 1);
  nodes_.emplace_back();
  slot_spheres_.assign(layout.size(), Eigen::Vector4d::Zero());
  // Without anchors the slot copies stay as set here (never read: every
  // contact then reports has_surface false) and the refit skips them.
  anchored_ = layout.anchor_count() > 0;
  slot_anchors_.assign(layout.size(),
                       Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  slot_faces_.assign(layout.size(), {});
  if (n > 0) build(0, 0, n, 1, layout);
  SphereState rest(layout);
  refit(rest);
  refits_ = 0;
}

std::int32_t SphereTree::split(std::int32_t begin, std::int32_t end,
                               const sphere_layout::SphereLayout& layout) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300);
  Eigen::Vector3d hi = Eigen::Vector3d::Constant(-1e300);
  for (std::int32_t i = begin; i < end; ++i) {
    const Eigen::Vector3d& c = layout.sphere(order_[i]).rest_centre_m;
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  const std::int32_t mid = begin + (end - begin) / 2;
  // Ties broken by sphere id, so the tree is the same on every machine.
  std::nth_element(order_.begin() + begin, order_.begin() + mid, order_.begin() + end,
                   [&](std::uint32_t a, std::uint32_t b) {
                     const double ca = layout.sphere(a).rest_centre_m[axis];
                     const double cb = layout.sphere(b).rest_centre_m[axis];
                     return ca < cb || (ca == cb && a < b);
                   });
  return mid;
}

void SphereTree::arrange_leaf(std::int32_t begin, std::int32_t end,
                              const sphere_layout::SphereLayout& layout,
                              std::vector<std::uint32_t>& out) {
  if (end - begin <= kBlockSize) {
    out.insert(out.end(), order_.begin() + begin, order_.begin() + end);
    return;
  }
  const std::int32_t mid = split(begin, end, layout);
  arrange_leaf(mid, end, layout, out);  // the right half first, as the query's walk
  arrange_leaf(begin, mid, layout, out);
}

void SphereTree::build(std::int32_t node, std::int32_t begin, std::int32_t end, int depth,
                       const sphere_layout::SphereLayout& layout) {
  depth_ = std::max(depth_, depth);
  if (end - begin <= kLeafSize) {
    nodes_[node].first = begin;
    nodes_[node].count = end - begin;
    // The spheres in the order a tree of kBlockSize leaves walked them.
    std::vector<std::uint32_t> arranged;
    arranged.reserve(static_cast<std::size_t>(end - begin));
    arrange_leaf(begin, end, layout, arranged);
    std::copy(arranged.begin(), arranged.end(), order_.begin() + begin);
    return;
  }
  const std::int32_t mid = split(begin, end, layout);
  const auto left = static_cast<std::int32_t>(nodes_.size());
  nodes_.emplace_back();
  nodes_.emplace_back();
  nodes_[node].first = left;
  nodes_[node].count = 0;
  build(left, begin, mid, depth + 1, layout);
  build(left + 1, mid, end, depth + 1, layout);
}

void SphereTree::refit(const SphereState& state) {
  const auto& centres = state.centres_m();
  const auto& radii = state.radii_m();
  const auto& anchors = state.anchors_m();
  const auto& faces = state.anchor_faces_m();
  for (std::size_t k = nodes_.size(); k-- > 0;) {
    SphereTreeNode& node = nodes_[k];
    if (node.count > 0) {
      const std::uint32_t first = order_[node.first];
      node.box_min_m = centres[first] - Eigen::Vector3d::Constant(radii[first]);
      node.box_max_m = centres[first] + Eigen::Vector3d::Constant(radii[first]);
      for (std::int32_t i = 1; i < node.count; ++i) {
        const std::uint32_t s = order_[node.first + i];
        node.box_min_m = node.box_min_m.cwiseMin(centres[s] - Eigen::Vector3d::Constant(radii[s]));
        node.box_max_m = node.box_max_m.cwiseMax(centres[s] + Eigen::Vector3d::Constant(radii[s]));
      }
      const Eigen::Vector3d middle = 0.5 * (node.box_min_m + node.box_max_m);
      node.reach_m = 0.0;
      for (std::int32_t i = 0; i < node.count; ++i) {
        const std::int32_t slot = node.first + i;
        const std::uint32_t s = order_[slot];
        slot_spheres_[static_cast<std::size_t>(slot)] << centres[s], radii[s];
        if (anchored_) {
          slot_anchors_[static_cast<std::size_t>(slot)] = anchors[s];
          slot_faces_[static_cast<std::size_t>(slot)] = faces[s];
        }
        node.reach_m = std::max(node.reach_m, (centres[s] - middle).norm() + radii[s]);
      }
    } else if (k > 0 || !order_.empty()) {
      const SphereTreeNode& a = nodes_[node.first];
      const SphereTreeNode& b = nodes_[node.first + 1];
      node.box_min_m = a.box_min_m.cwiseMin(b.box_min_m);
      node.box_max_m = a.box_max_m.cwiseMax(b.box_max_m);
      // Both bound every sphere point's distance from the box's middle.
      const Eigen::Vector3d middle = 0.5 * (node.box_min_m + node.box_max_m);
      const double through_children =
          std::max((0.5 * (a.box_min_m + a.box_max_m) - middle).norm() + a.reach_m,
                   (0.5 * (b.box_min_m + b.box_max_m) - middle).norm() + b.reach_m);
      node.reach_m = std::min(through_children, 0.5 * (node.box_max_m - node.box_min_m).norm());
    }
  }
  ++refits_;
}

}  // namespace fahr::collision
