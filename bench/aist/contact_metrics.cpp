// Contact recall and depth error (see contact_metrics.h).
#include "contact_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "sections.h"
#include "stats.h"

namespace fahr::aist_bench {

ContactMetrics::ContactMetrics(const Scene& scene) : scene_(scene) {}

namespace {

// Generalised winding number of a closed triangle surface at p (Jacobson et
// al. 2013, from van Oosterom and Strackee's solid angle): about 1 inside, 0 outside.
double winding_number(const Eigen::Vector3d& p, const std::vector<Eigen::Vector3d>& v,
                      const std::vector<geometry::Triangle>& triangles) {
  double sum = 0.0;
  for (const auto& t : triangles) {
    const Eigen::Vector3d a = v[t[0]] - p, b = v[t[1]] - p, c = v[t[2]] - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double numerator = a.dot(b.cross(c));
    const double denominator = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
    sum += 2.0 * std::atan2(numerator, denominator);
  }
  return sum / (4.0 * 3.14159265358979323846);
}

}  // namespace

void ContactMetrics::add_tick(const collision::ContactBuffer& aist,
                              const collision::SphereState& state,
                              const std::vector<collision::TriangleContact>& base,
                              const Eigen::Isometry3d& world_from_blade,
                              std::span<const double> positions_m) {
  std::vector<Eigen::Vector3d> deformed;
  bool have_deformed = false;
  auto inside_tongue = [&](const Eigen::Vector3d& p) {
    if (!have_deformed) {
      for (const auto node : scene_.surface_to_node) {
        const auto n = static_cast<std::size_t>(node);
        deformed.emplace_back(positions_m[3 * n], positions_m[3 * n + 1], positions_m[3 * n + 2]);
      }
      have_deformed = true;
    }
    return winding_number(p, deformed, scene_.boundary.triangles()) > 0.5;
  };
  const auto& centres = state.centres_m();
  const auto& radii = state.radii_m();
  auto in_region = [&](const collision::SphereContact& a, const Eigen::Vector3d& p) {
    return (p - centres[a.sphere_id]).norm() <= radii[a.sphere_id] + kRegionSlackM;
  };
  const Eigen::Isometry3d blade_from_world = world_from_blade.inverse();
  // Per AIST contact: the deepest verified baseline penetration in its region.
  std::vector<double> region_deepest(aist.size(), -1.0);
  for (const auto& b : base) {
    // The tissue-side point: the penetrating tongue vertex, or the blade
    // vertex that is inside the tongue.
    const Eigen::Vector3d p =
        b.tissue_vertex >= 0 ? Eigen::Vector3d(b.point_m - b.depth_m * b.normal) : b.point_m;
    // Verified against exact geometry: a tongue vertex must be inside the
    // blade (its exact field), a blade vertex inside the deformed tongue (its
    // winding number); a vertex merely behind a face is a false contact.
    double exact = b.depth_m;
    if (b.tissue_vertex >= 0) {
      exact = -scene_.blade_sdf.query_exact(blade_from_world * p).distance_m;
      if (exact <= 0.0) {
        ++base_false_;
        continue;
      }
    } else if (!inside_tongue(p)) {
      ++base_false_;
      continue;
    }
    ++base_total_;
    bool recalled = false, near = false, by_surface = false;
    double aist_depth = 0.0, nearest_depth = 0.0,
           nearest_gap = std::numeric_limits<double>::infinity();
    double nearest_surface = 0.0;
    // The surface point measuring at p: the reporting sphere's anchor nearest
    // p (a sphere without one stands for the surface by its own; its
    // distance is that of its surface); [1]: candidates' anchors too.
    double anchor_gap[2] = {std::numeric_limits<double>::infinity(),
                            std::numeric_limits<double>::infinity()};
    double anchor_depth[2] = {0.0, 0.0}, anchor_field = 0.0;
    std::size_t aist_index = 0;
    for (const auto& a : aist) {
      const std::size_t index = aist_index++;
      if (!in_region(a, p)) continue;
      near = true;
      by_surface = by_surface || !a.candidate || (a.has_surface && a.surface_depth_m > 0.0);
      const double surface = a.has_surface ? a.surface_depth_m : a.depth_m;
      const double gap = (p - centres[a.sphere_id]).norm() - radii[a.sphere_id];
      const double to_anchor = a.has_surface ? (p - a.surface_point_m).norm() : gap;
      for (int with_candidates = 0; with_candidates < 2; ++with_candidates) {
        if ((a.candidate && with_candidates == 0) || !(to_anchor < anchor_gap[with_candidates]))
          continue;
        anchor_gap[with_candidates] = to_anchor;
        anchor_depth[with_candidates] = surface;
        if (with_candidates == 0) {
          anchor_field =
              a.has_surface
                  ? -scene_.blade_sdf.query_exact(blade_from_world * a.surface_point_m).distance_m
                  : a.depth_m;
        }
      }
      if (a.candidate) continue;
      region_deepest[index] = std::max(region_deepest[index], exact);
      recalled = true;
      aist_depth = std::max(aist_depth, a.depth_m);
      if (gap < nearest_gap) {
        nearest_gap = gap;
        nearest_depth = a.depth_m;
        nearest_surface = surface;
      }
    }
    // A surface point outside the blade reports no penetration there: 0, as
    // for a point no sphere reports.
    const double surface_at_p = std::max(anchor_depth[0], 0.0);
    const double surface_at_p_candidates = std::max(anchor_depth[1], 0.0);
    all_exact_depth_m_.push_back(exact);
    all_deepest_error_m_.push_back(std::abs(aist_depth - exact));
    all_nearest_error_m_.push_back(std::abs(nearest_depth - exact));
    base_recalled_surface_ += by_surface ? 1 : 0;
    if (recalled) anchor_distance_m_.push_back(anchor_gap[0]);
    for (const int kind : {b.tissue_vertex >= 0 ? 0 : 1, 2}) {
      sphere_nearest_error_m_[kind].push_back(std::abs(nearest_depth - exact));
      nearest_surface_error_m_[kind].push_back(std::abs(std::max(nearest_surface, 0.0) - exact));
      anchor_error_m_[kind].push_back(std::abs(surface_at_p - exact));
      anchor_candidates_error_m_[kind].push_back(std::abs(surface_at_p_candidates - exact));
      anchor_field_error_m_[kind].push_back(std::abs(std::max(anchor_field, 0.0) - exact));
    }
    if (!recalled) {
      // Why it was missed: the distance from p to the (deformed) sphere union.
      double gap = std::numeric_limits<double>::infinity();
      for (std::size_t i = 0; i < centres.size(); ++i)
        gap = std::min(gap, (p - centres[i]).norm() - radii[i]);
      if (near) {
        ++miss_candidate_;
      } else if (gap <= kRegionSlackM) {
        ++miss_standoff_;
      } else {
        ++miss_detached_;
      }
    }
    base_recalled_ += recalled ? 1 : 0;
    base_recalled_near_ += near ? 1 : 0;
    if (exact >= kDeepM) {
      ++deep_total_;
      deep_recalled_ += recalled ? 1 : 0;
    }
    if (exact >= kDeeperM) {
      ++deeper_total_;
      deeper_recalled_ += recalled ? 1 : 0;
      deeper_recalled_near_ += near ? 1 : 0;
    }
    if (b.tissue_vertex >= 0) {
      exact_depth_m_.push_back(exact);
      aist_depth_error_m_.push_back(std::abs(aist_depth - exact));
      base_depth_error_m_.push_back(std::abs(b.depth_m - exact));
    }
  }
  std::size_t aist_index = 0;
  for (const auto& a : aist) {
    const double deepest = region_deepest[aist_index++];
    if (a.candidate || deepest < 0.0) continue;
    const double surface = std::max(a.has_surface ? a.surface_depth_m : a.depth_m, 0.0);
    contact_deepest_m_.push_back(deepest);
    contact_sphere_error_m_.push_back(std::abs(std::max(a.depth_m, 0.0) - deepest));
    contact_surface_error_m_.push_back(std::abs(surface - deepest));
  }
  for (const auto& a : aist) {
    if (a.candidate) continue;
    ++aist_total_;
    bool matched = false;
    for (const auto& b : base) {
      const Eigen::Vector3d p =
          b.tissue_vertex >= 0 ? Eigen::Vector3d(b.point_m - b.depth_m * b.normal) : b.point_m;
      matched = matched || in_region(a, p);
    }
    aist_unmatched_ += matched ? 0 : 1;
  }
  contact_ticks_ += (aist.size() > 0 || !base.empty()) ? 1 : 0;
  ticks_both_ += (aist.size() > 0 && !base.empty()) ? 1 : 0;
}

double ContactMetrics::recall() const {
  return base_total_ > 0 ? static_cast<double>(base_recalled_) / static_cast<double>(base_total_)
                         : 1.0;
}

double ContactMetrics::recall_near() const {
  return base_total_ > 0
             ? static_cast<double>(base_recalled_near_) / static_cast<double>(base_total_)
             : 1.0;
}

double ContactMetrics::recall_deeper() const {
  return deeper_total_ > 0
             ? static_cast<double>(deeper_recalled_) / static_cast<double>(deeper_total_)
             : 1.0;
}

void ContactMetrics::print() const {
  auto ratio = [](std::size_t a, std::size_t b) {
    return b > 0 ? 100.0 * static_cast<double>(a) / static_cast<double>(b) : 100.0;
  };
  std::printf(
      "\nRecall: a baseline contact's tissue-side point (the tongue vertex inside the blade, or "
      "the blade vertex "
      "inside the tongue) is recalled when it lies in the region of an AIST sphere that reports "
      "contact: within "
      "its radius + %.1f mm (the coverage target). \"with candidates\": an AIST sphere within the "
      "candidate margin (not touching) counts as well. Baseline tongue-vertex contacts that the "
      "exact blade field puts "
      "outside the blade are the baseline's false contacts and are left out. Ticks with contacts: "
      "%zu (both: %zu).\n\n",
      kRegionSlackM * 1e3, contact_ticks_, ticks_both_);
  std::printf(
      "| baseline contacts (verified) | recall | with candidates | deeper than %.2f mm | recall | "
      "deeper than %.2f mm | recall | with candidates | baseline false contacts | AIST contacts | "
      "AIST with no baseline contact in region |\n",
      kDeepM * 1e3, kDeeperM * 1e3);
  std::printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  std::printf(
      "| %zu | %.2f%% | %.2f%% | %zu | %.2f%% | %zu | %.2f%% | %.2f%% | %zu | %zu | %zu (%.1f%%) "
      "|\n",
      base_total_, ratio(base_recalled_, base_total_), ratio(base_recalled_near_, base_total_),
      deep_total_, ratio(deep_recalled_, deep_total_), deeper_total_,
      ratio(deeper_recalled_, deeper_total_), ratio(deeper_recalled_near_, deeper_total_),
      base_false_, aist_total_, aist_unmatched_, ratio(aist_unmatched_, aist_total_));
  const std::size_t missed = base_total_ - base_recalled_;
  std::printf(
      "\nMissed baseline contacts (%zu), by cause: an AIST sphere covering the point is reported "
      "as a "
      "candidate (within %.2f mm of the blade, resting where the FEM's projection put it): %zu "
      "(%.1f%%); the "
      "sphere union lies within %.1f mm of the point but no covering sphere reaches the blade (the "
      "union stands "
      "inside the deformed surface): %zu (%.1f%%); the union lies farther than that from the point "
      "(coverage lost "
      "under the deformation): %zu (%.1f%%).\n",
      missed, kCandidateMarginM * 1e3, miss_candidate_, ratio(miss_candidate_, missed),
      kRegionSlackM * 1e3, miss_standoff_, ratio(miss_standoff_, missed), miss_detached_,
      ratio(miss_detached_, missed));
  std::printf(
      "\nDepth error at each baseline tongue-vertex contact (%zu): the exact penetration of that "
      "vertex into the "
      "blade (-sdf, exact query; median %.3f mm, max %.3f mm) against the deepest AIST contact "
      "whose region holds "
      "the vertex, and against the baseline's own face depth.\n\n",
      exact_depth_m_.size(), percentile(exact_depth_m_, 50) * 1e3,
      percentile(exact_depth_m_, 100) * 1e3);
  std::printf(
      "| method | median (mm) | p95 (mm) | p99 (mm) | max (mm) |\n| --- | --- | --- | --- | --- "
      "|\n");
  std::printf("| AIST | %.3f | %.3f | %.3f | %.3f |\n", percentile(aist_depth_error_m_, 50) * 1e3,
              percentile(aist_depth_error_m_, 95) * 1e3, percentile(aist_depth_error_m_, 99) * 1e3,
              percentile(aist_depth_error_m_, 100) * 1e3);
  std::printf("| baseline | %.3f | %.3f | %.3f | %.3f |\n",
              percentile(base_depth_error_m_, 50) * 1e3, percentile(base_depth_error_m_, 95) * 1e3,
              percentile(base_depth_error_m_, 99) * 1e3,
              percentile(base_depth_error_m_, 100) * 1e3);
  std::printf(
      "\nDepth error at every verified baseline contact (%zu; exact depth median %.3f mm, p95 %.3f "
      "mm, max %.3f mm): "
      "a tongue vertex's exact penetration as above, a blade vertex's depth behind the deformed "
      "tissue face the "
      "baseline found it under (inside the tongue by its winding number). AIST depth at the point: "
      "the deepest "
      "reporting sphere whose region holds it, or the reporting sphere whose surface is nearest "
      "the point "
      "(0 when none).\n\n",
      all_exact_depth_m_.size(), percentile(all_exact_depth_m_, 50) * 1e3,
      percentile(all_exact_depth_m_, 95) * 1e3, percentile(all_exact_depth_m_, 100) * 1e3);
  std::printf(
      "| AIST depth at the point | median (mm) | p95 (mm) | p99 (mm) | max (mm) |\n| --- | --- | "
      "--- | --- | --- |\n");
  for (const auto* e : {&all_deepest_error_m_, &all_nearest_error_m_}) {
    std::printf("| %s | %.3f | %.3f | %.3f | %.3f |\n",
                e == &all_deepest_error_m_ ? "deepest sphere" : "nearest sphere",
                percentile(*e, 50) * 1e3, percentile(*e, 95) * 1e3, percentile(*e, 99) * 1e3,
                percentile(*e, 100) * 1e3);
  }
  std::printf(
      "\nSurface depth (SphereContact::surface_depth_m: the depth of the sphere's surface point, "
      "on its "
      "anchor face of the deformed tissue, behind the blade's tangent plane at the contact) "
      "against the sphere "
      "depth, at the same verified contacts, by kind: %zu tongue vertices inside the blade, %zu "
      "blade vertices "
      "inside the tongue. \"nearest surface point\": of the reporting spheres whose region holds "
      "the point, the "
      "one whose surface point is nearest it (median distance %.3f mm, p95 %.3f mm over recalled "
      "points); "
      "\"the field at it\": the blade's exact field at that surface point instead (not what the "
      "query reports: "
      "a diagnostic). A depth <= 0 (that surface point clear of the blade) counts as 0. Recall "
      "counting a "
      "candidate sphere whose surface point is inside the blade as reporting: %.2f%%.\n\n",
      anchor_error_m_[0].size(), anchor_error_m_[1].size(),
      percentile(anchor_distance_m_, 50) * 1e3, percentile(anchor_distance_m_, 95) * 1e3,
      ratio(base_recalled_surface_, base_total_));
  std::printf(
      "| AIST depth at the point | all: median / p95 / p99 / max (mm) | tongue vertices: median / "
      "p95 (mm) | blade vertices: median / p95 (mm) |\n| --- | --- | --- | --- |\n");
  auto row = [](const char* name, const std::vector<double>* e) {
    std::printf("| %s | %.3f / %.3f / %.3f / %.3f | %.3f / %.3f | %.3f / %.3f |\n", name,
                percentile(e[2], 50) * 1e3, percentile(e[2], 95) * 1e3, percentile(e[2], 99) * 1e3,
                percentile(e[2], 100) * 1e3, percentile(e[0], 50) * 1e3, percentile(e[0], 95) * 1e3,
                percentile(e[1], 50) * 1e3, percentile(e[1], 95) * 1e3);
  };
  row("nearest sphere, sphere depth (before)", sphere_nearest_error_m_);
  row("nearest sphere, surface depth", nearest_surface_error_m_);
  row("nearest surface point, surface depth", anchor_error_m_);
  row("nearest surface point, candidates' too", anchor_candidates_error_m_);
  row("nearest surface point, the field at it", anchor_field_error_m_);
  std::printf(
      "\nPer AIST contact (%zu reporting spheres with a verified baseline contact in their "
      "region): the "
      "sphere's depth against the deepest exact penetration among those baseline contacts (median "
      "%.3f mm, "
      "p95 %.3f mm), the penetration depth of the contact the sphere stands for. A sphere reports "
      "one depth; "
      "the baseline reports one per vertex, and on the blade's rounded rim the vertices under one "
      "tissue face "
      "range from its deepest point to 0, which the per-point tables above compare with that one "
      "depth.\n\n",
      contact_deepest_m_.size(), percentile(contact_deepest_m_, 50) * 1e3,
      percentile(contact_deepest_m_, 95) * 1e3);
  std::printf(
      "| AIST depth | median (mm) | p95 (mm) | p99 (mm) | max (mm) |\n| --- | --- | --- | --- | "
      "--- |\n");
  for (const auto* e : {&contact_sphere_error_m_, &contact_surface_error_m_}) {
    std::printf("| %s | %.3f | %.3f | %.3f | %.3f |\n",
                e == &contact_sphere_error_m_ ? "sphere depth"
                                              : "surface depth (SphereContact::surface_depth_m)",
                percentile(*e, 50) * 1e3, percentile(*e, 95) * 1e3, percentile(*e, 99) * 1e3,
                percentile(*e, 100) * 1e3);
  }
}

}  // namespace fahr::aist_bench
