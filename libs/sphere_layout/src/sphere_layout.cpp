// SphereLayout: checks of the assembled layout, counts and the fingerprint.
#include "fahr/sphere_layout/sphere_layout.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

namespace fahr::sphere_layout {
namespace {

constexpr std::uint64_t kFnvOffset = 14695981039346656037ULL;
constexpr std::uint64_t kFnvPrime = 1099511628211ULL;

void hash_bytes(std::uint64_t& hash, const void* data, std::size_t bytes) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < bytes; ++i) {
    hash ^= p[i];
    hash *= kFnvPrime;
  }
}

// Fields one by one: the struct's padding bytes are not data.
void hash_record(std::uint64_t& hash, const SphereRecord& s) {
  hash_bytes(hash, s.rest_centre_m.data(), 3 * sizeof(double));
  hash_bytes(hash, &s.rest_radius_m, sizeof(double));
  hash_bytes(hash, &s.rest_linked_volume_m3, sizeof(double));
  hash_bytes(hash, &s.first_link, sizeof(std::uint32_t));
  hash_bytes(hash, &s.link_count, sizeof(std::uint32_t));
  hash_bytes(hash, &s.first_tet, sizeof(std::uint32_t));
  hash_bytes(hash, &s.tet_count, sizeof(std::uint32_t));
  hash_bytes(hash, &s.level, sizeof(std::uint8_t));
  hash_bytes(hash, &s.origin, sizeof(SphereOrigin));
}

}  // namespace

SphereLayout::SphereLayout(std::vector<SphereRecord> spheres, std::vector<std::uint32_t> link_nodes,
                           std::vector<double> link_weights, std::vector<std::uint32_t> linked_tets,
                           std::vector<geometry::Tet> tets, std::size_t node_count,
                           int finest_level, double coarse_radius_m)
    : spheres_(std::move(spheres)),
      link_nodes_(std::move(link_nodes)),
      link_weights_(std::move(link_weights)),
      linked_tets_(std::move(linked_tets)),
      tets_(std::move(tets)),
      node_count_(node_count),
      finest_level_(finest_level),
      coarse_radius_m_(coarse_radius_m) {
  if (link_nodes_.size() != link_weights_.size()) {
    throw std::invalid_argument("sphere layout: node and weight arrays differ in length");
  }
  for (std::size_t i = 0; i < spheres_.size(); ++i) {
    const SphereRecord& s = spheres_[i];
    if (s.first_link + s.link_count > link_nodes_.size() || s.link_count == 0 ||
        s.first_tet + s.tet_count > linked_tets_.size() || s.tet_count == 0) {
      throw std::invalid_argument("sphere layout: sphere " + std::to_string(i) +
                                  " has links out of range or none");
    }
    double sum = 0.0;
    for (std::uint32_t k = 0; k < s.link_count; ++k) {
      const double w = link_weights_[s.first_link + k];
      if (!(w >= 0.0) || link_nodes_[s.first_link + k] >= node_count_) {
        throw std::invalid_argument("sphere layout: sphere " + std::to_string(i) +
                                    " has a negative weight or a node out of range");
      }
      sum += w;
    }
    if (std::abs(sum - 1.0) > kWeightSumTolerance || !(s.rest_radius_m > 0.0)) {
      throw std::invalid_argument("sphere layout: sphere " + std::to_string(i) +
                                  " has weights not summing to 1 or a radius <= 0");
    }
  }
}

void SphereLayout::set_anchors(std::vector<SurfaceAnchor> anchors,
                               std::vector<std::uint8_t> has_anchor) {
  if (anchors.size() != has_anchor.size() ||
      (!anchors.empty() && anchors.size() != spheres_.size())) {
    throw std::invalid_argument("sphere layout: " + std::to_string(anchors.size()) +
                                " anchors and " + std::to_string(has_anchor.size()) +
                                " flags for " + std::to_string(spheres_.size()) + " spheres");
  }
  for (std::size_t i = 0; i < anchors.size(); ++i) {
    if (has_anchor[i] == 0) continue;
    double sum = 0.0;
    for (int k = 0; k < 3; ++k) {
      const double w = anchors[i].weights[static_cast<std::size_t>(k)];
      if (!(w >= 0.0) || anchors[i].nodes[static_cast<std::size_t>(k)] >= node_count_) {
        throw std::invalid_argument("sphere layout: the anchor of sphere " + std::to_string(i) +
                                    " has a negative or NaN weight or a node out of range");
      }
      sum += w;
    }
    if (std::abs(sum - 1.0) > kWeightSumTolerance || !anchors[i].rest_point_m.allFinite()) {
      throw std::invalid_argument("sphere layout: the anchor of sphere " + std::to_string(i) +
                                  " has weights not summing to 1 or a non-finite rest point");
    }
  }
  anchors_ = std::move(anchors);
  has_anchor_ = std::move(has_anchor);
}

std::size_t SphereLayout::anchor_count() const {
  return static_cast<std::size_t>(
      std::count_if(has_anchor_.begin(), has_anchor_.end(), [](std::uint8_t f) { return f != 0; }));
}

std::size_t SphereLayout::count(SphereOrigin origin) const {
  return static_cast<std::size_t>(std::count_if(
      spheres_.begin(), spheres_.end(), [&](const SphereRecord& s) { return s.origin == origin; }));
}

std::size_t SphereLayout::count_at_level(int level) const {
  return static_cast<std::size_t>(std::count_if(
      spheres_.begin(), spheres_.end(),
      [&](const SphereRecord& s) { return s.origin == SphereOrigin::kGrid && s.level == level; }));
}

std::uint64_t SphereLayout::fingerprint() const {
  std::uint64_t hash = kFnvOffset;
  for (const SphereRecord& s : spheres_) hash_record(hash, s);
  hash_bytes(hash, link_nodes_.data(), link_nodes_.size() * sizeof(std::uint32_t));
  hash_bytes(hash, link_weights_.data(), link_weights_.size() * sizeof(double));
  hash_bytes(hash, linked_tets_.data(), linked_tets_.size() * sizeof(std::uint32_t));
  for (std::size_t i = 0; i < anchors_.size(); ++i) {
    hash_bytes(hash, &has_anchor_[i], sizeof(std::uint8_t));
    hash_bytes(hash, anchors_[i].nodes.data(), 3 * sizeof(std::uint32_t));
    hash_bytes(hash, anchors_[i].weights.data(), 3 * sizeof(double));
    hash_bytes(hash, anchors_[i].rest_point_m.data(), 3 * sizeof(double));
    for (const Eigen::Vector3d& p : anchors_[i].rest_face_m)
      hash_bytes(hash, p.data(), 3 * sizeof(double));
  }
  return hash;
}

SphereLayout concatenate(std::span<const SphereLayout* const> layouts,
                         std::span<const std::size_t> node_offsets) {
  if (layouts.size() != node_offsets.size() || layouts.empty())
    throw std::invalid_argument("concatenate: one node offset per layout, at least one layout");
  std::vector<SphereRecord> spheres;
  std::vector<std::uint32_t> link_nodes;
  std::vector<double> link_weights;
  std::vector<std::uint32_t> linked_tets;
  std::vector<geometry::Tet> tets;
  std::vector<SurfaceAnchor> anchors;
  std::vector<std::uint8_t> has_anchor;
  std::size_t node_count = 0;
  int finest_level = 0;
  double coarse_radius_m = 0.0;
  bool any_anchor = false;
  for (const SphereLayout* layout : layouts) any_anchor = any_anchor || layout->anchor_count() > 0;
  for (std::size_t b = 0; b < layouts.size(); ++b) {
    const SphereLayout& layout = *layouts[b];
    const std::size_t node_offset = node_offsets[b];
    if (node_offset != node_count)
      throw std::invalid_argument("concatenate: node offsets must follow the bodies' node counts");
    const auto node = [&](std::uint32_t n) { return static_cast<std::uint32_t>(n + node_offset); };
    const auto tet_offset = static_cast<std::uint32_t>(tets.size());
    for (std::size_t i = 0; i < layout.size(); ++i) {
      SphereRecord record = layout.sphere(i);
      record.first_link = static_cast<std::uint32_t>(link_nodes.size());
      record.first_tet = static_cast<std::uint32_t>(linked_tets.size());
      for (const std::uint32_t n : layout.nodes(i)) link_nodes.push_back(node(n));
      for (const double w : layout.weights(i)) link_weights.push_back(w);
      for (const std::uint32_t t : layout.tets_of(i)) linked_tets.push_back(t + tet_offset);
      spheres.push_back(record);
      if (any_anchor) {
        const SurfaceAnchor* anchor = layout.anchor(i);
        SurfaceAnchor shifted = anchor != nullptr ? *anchor : SurfaceAnchor{};
        for (auto& n : shifted.nodes) n = node(n);
        anchors.push_back(shifted);
        has_anchor.push_back(anchor != nullptr ? 1 : 0);
      }
    }
    for (geometry::Tet t : layout.tets()) {
      for (auto& n : t) n = static_cast<geometry::Index>(static_cast<std::size_t>(n) + node_offset);
      tets.push_back(t);
    }
    node_count += layout.node_count();
    finest_level = std::max(finest_level, layout.finest_level());
    coarse_radius_m = std::max(coarse_radius_m, layout.coarse_radius_m());
  }
  SphereLayout joined(std::move(spheres), std::move(link_nodes), std::move(link_weights),
                      std::move(linked_tets), std::move(tets), node_count, finest_level,
                      coarse_radius_m);
  if (any_anchor) joined.set_anchors(std::move(anchors), std::move(has_anchor));
  return joined;
}

}  // namespace fahr::sphere_layout
