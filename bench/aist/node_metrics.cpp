// Node-level recall and depth error (see node_metrics.h).
#include "node_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "contact_metrics.h"
#include "sections.h"
#include "stats.h"

namespace fahr::aist_bench {

NodeMetrics::NodeMetrics(const Scene& scene) : scene_(scene) {
  std::size_t node_count = 0;
  for (const auto n : scene.surface_to_node)
    node_count = std::max(node_count, static_cast<std::size_t>(n) + 1);
  node_to_vertex_.assign(node_count, -1);
  for (std::size_t v = 0; v < scene.surface_to_node.size(); ++v) {
    node_to_vertex_[static_cast<std::size_t>(scene.surface_to_node[v])] =
        static_cast<std::int32_t>(v);
  }
  for (std::size_t n = 0; n < node_count; ++n) {
    if (node_to_vertex_[n] >= 0) nodes_.push_back(static_cast<std::uint32_t>(n));
  }
  base_stamp_.assign(scene.surface_to_node.size(), 0);
  base_depth_m_.assign(scene.surface_to_node.size(), 0.0);
}

void NodeMetrics::add_tick(const collision::ContactBuffer& aist,
                           const collision::SphereState& state,
                           const std::vector<collision::TriangleContact>& base,
                           const Eigen::Isometry3d& world_from_blade,
                           std::span<const double> positions_m) {
  ++tick_;
  for (const auto& b : base) {
    if (b.tissue_vertex < 0) continue;
    const auto v = static_cast<std::size_t>(b.tissue_vertex);
    base_stamp_[v] = tick_;
    base_depth_m_[v] = b.depth_m;
  }
  const Eigen::Isometry3d blade_from_world = world_from_blade.inverse();
  const auto& centres = state.centres_m();
  const auto& radii = state.radii_m();
  for (const auto node : nodes_) {
    const std::size_t first = 3 * static_cast<std::size_t>(node);
    const Eigen::Vector3d p(positions_m[first], positions_m[first + 1], positions_m[first + 2]);
    const double exact = -scene_.blade_sdf.query(blade_from_world * p).distance_m;
    if (!(exact > 0.0)) continue;
    bool recalled = false, near = false;
    double aist_depth = 0.0, surface_depth = 0.0,
           anchor_gap = std::numeric_limits<double>::infinity();
    for (const auto& a : aist) {
      const double gap = (p - centres[a.sphere_id]).norm() - radii[a.sphere_id];
      if (gap > ContactMetrics::kRegionSlackM) continue;
      near = true;
      if (a.candidate) continue;
      recalled = true;
      aist_depth = std::max(aist_depth, a.depth_m);
      const double to_anchor = a.has_surface ? (p - a.surface_point_m).norm() : gap;
      if (to_anchor < anchor_gap) {
        anchor_gap = to_anchor;
        surface_depth = a.has_surface ? a.surface_depth_m : a.depth_m;
      }
    }
    surface_error_m_.push_back(std::abs(std::max(surface_depth, 0.0) - exact));
    const auto vertex = static_cast<std::size_t>(node_to_vertex_[node]);
    const bool by_base = base_stamp_[vertex] == tick_;
    for (int c = 0; c < kClasses; ++c) {
      if (exact < kClassDepthM[c]) continue;
      ++total_[c];
      aist_[c] += recalled ? 1 : 0;
      aist_near_[c] += near ? 1 : 0;
      base_[c] += by_base ? 1 : 0;
    }
    if (!recalled) {
      double gap = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < centres.size(); ++i)
        gap = std::min(gap, (p - centres[i]).norm() - radii[i]);
      if (near) {
        ++miss_candidate_;
      } else if (gap <= ContactMetrics::kRegionSlackM) {
        ++miss_standoff_;
      } else {
        ++miss_detached_;
      }
    } else {
      recalled_error_m_.push_back(std::abs(aist_depth - exact));
    }
    exact_m_.push_back(exact);
    aist_error_m_.push_back(std::abs(aist_depth - exact));
    aist_signed_error_m_.push_back(aist_depth - exact);
    base_error_m_.push_back(std::abs((by_base ? base_depth_m_[vertex] : 0.0) - exact));
  }
}

void NodeMetrics::print() const {
  auto ratio = [](std::size_t a, std::size_t b) {
    return b > 0 ? 100.0 * static_cast<double>(a) / static_cast<double>(b) : 100.0;
  };
  std::printf(
      "\nGround truth: tongue surface nodes inside the blade (its field, exact near the surface), "
      "counted once "
      "per tick. AIST: recalled when a sphere reporting contact holds the node within its radius + "
      "%.1f mm; "
      "with candidates, a candidate sphere counts too. Baseline: recalled when it reports that "
      "vertex.\n\n",
      ContactMetrics::kRegionSlackM * 1e3);
  std::printf(
      "| node depth | nodes in the blade | AIST recall | AIST with candidates | baseline recall "
      "|\n| --- | --- | --- | --- | --- |\n");
  for (int c = 0; c < kClasses; ++c) {
    std::printf("| > %.2f mm | %zu | %.2f%% | %.2f%% | %.2f%% |\n", kClassDepthM[c] * 1e3,
                total_[c], ratio(aist_[c], total_[c]), ratio(aist_near_[c], total_[c]),
                ratio(base_[c], total_[c]));
  }
  const std::size_t missed = total_[0] - aist_[0];
  std::printf(
      "\nNodes the AIST missed (%zu), by cause: covered by a candidate sphere only (within %.2f mm "
      "of the blade): "
      "%zu (%.1f%%); the sphere union within %.1f mm but no covering sphere reaches the blade: %zu "
      "(%.1f%%); the "
      "union farther than that: %zu (%.1f%%).\n",
      missed, kCandidateMarginM * 1e3, miss_candidate_, ratio(miss_candidate_, missed),
      ContactMetrics::kRegionSlackM * 1e3, miss_standoff_, ratio(miss_standoff_, missed),
      miss_detached_, ratio(miss_detached_, missed));
  std::printf(
      "\nDepth error per node in the blade (%zu; exact penetration median %.3f mm, p95 %.3f mm, "
      "max %.3f mm); "
      "AIST signed error (AIST - exact) median %.3f mm; AIST over recalled nodes only: %zu.\n\n",
      exact_m_.size(), percentile(exact_m_, 50) * 1e3, percentile(exact_m_, 95) * 1e3,
      percentile(exact_m_, 100) * 1e3, percentile(aist_signed_error_m_, 50) * 1e3,
      recalled_error_m_.size());
  std::printf(
      "| method | median (mm) | p95 (mm) | p99 (mm) | max (mm) |\n| --- | --- | --- | --- | --- "
      "|\n");
  auto row = [](const char* name, const std::vector<double>& e) {
    std::printf("| %s | %.3f | %.3f | %.3f | %.3f |\n", name, percentile(e, 50) * 1e3,
                percentile(e, 95) * 1e3, percentile(e, 99) * 1e3, percentile(e, 100) * 1e3);
  };
  row("AIST", aist_error_m_);
  row("AIST, recalled nodes", recalled_error_m_);
  row("AIST surface depth (nearest surface point)", surface_error_m_);
  row("baseline", base_error_m_);
}

}  // namespace fahr::aist_bench
