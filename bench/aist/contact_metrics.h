// Recall of the AIST contacts against the baseline's and the depth error of
// both against an exact reference (see the definitions in print()).
#pragma once

#include <Eigen/Geometry>
#include <span>
#include <vector>

#include "fahr/collision/contact_buffer.h"
#include "fahr/collision/sphere_state.h"
#include "fahr/collision/triangle_baseline.h"
#include "scene.h"

namespace fahr::aist_bench {

class ContactMetrics {
 public:
  explicit ContactMetrics(const Scene& scene);
  // One tick's contacts; with_reference computes the exact depth reference
  // (dense samples of the deformed boundary against the blade's field).
  void add_tick(const collision::ContactBuffer& aist, const collision::SphereState& state,
                const std::vector<collision::TriangleContact>& base,
                const Eigen::Isometry3d& world_from_blade, std::span<const double> positions_m);
  void print() const;
  double recall() const;
  double recall_deeper() const;
  double recall_near()
      const;  // counting candidate spheres too  // over verified contacts deeper than kDeeperM

  // Baseline contacts shallower than this are also counted apart: the sphere
  // union may lie up to the coverage (about 0.4 mm) inside the surface, so a
  // graze of a few micrometres is below what it resolves, m.
  static constexpr double kDeepM = 0.1e-3;
  // A baseline contact point lies in an AIST sphere's region when it is
  // within the sphere grown by this: the coverage target, the distance by
  // which the boundary may stand off the sphere union, m.
  static constexpr double kRegionSlackM = 0.5e-3;
  // The second depth class: the closure's tolerance, below which the sphere
  // union may stand inside the surface by construction, m.
  static constexpr double kDeeperM = 0.25e-3;

 private:
  const Scene& scene_;
  std::size_t base_total_ = 0, base_recalled_ = 0, base_recalled_near_ = 0, base_false_ = 0;
  std::size_t deeper_recalled_near_ = 0;
  std::size_t miss_candidate_ = 0, miss_standoff_ = 0, miss_detached_ = 0;  // see print()
  std::size_t deep_total_ = 0, deep_recalled_ = 0, deeper_total_ = 0, deeper_recalled_ = 0;
  std::size_t aist_total_ = 0, aist_unmatched_ = 0;
  std::size_t contact_ticks_ = 0, ticks_both_ = 0;
  std::vector<double> aist_depth_error_m_, base_depth_error_m_, exact_depth_m_;
  // Over every verified contact, tongue and blade vertices alike.
  std::vector<double> all_exact_depth_m_, all_deepest_error_m_, all_nearest_error_m_;
  // The surface depth (SphereContact::surface_depth_m) at every verified
  // contact, per kind of contact (0: tongue vertex, 1: blade vertex, 2: all):
  // of the nearest sphere as above, and of the reporting sphere in whose
  // region the point lies whose surface point is nearest the point (the
  // surface that measures there), also with candidates' surface points, and
  // the blade's exact field at that surface point (a diagnostic); the
  // distance of that surface point from the point.
  static constexpr int kKinds = 3;
  std::vector<double> nearest_surface_error_m_[kKinds], anchor_error_m_[kKinds],
      anchor_field_error_m_[kKinds];
  std::vector<double> anchor_candidates_error_m_[kKinds];  // candidates' anchors too
  std::vector<double> sphere_nearest_error_m_[kKinds];     // the old figure, split by kind
  std::vector<double> anchor_distance_m_;
  std::size_t base_recalled_surface_ = 0;
  // Per reporting sphere with a verified baseline contact in its region: the
  // deepest exact penetration there, and the errors of its sphere and
  // surface depths against it.
  std::vector<double> contact_deepest_m_, contact_sphere_error_m_,
      contact_surface_error_m_;  // a reporting sphere, or a candidate whose anchor is inside
};

}  // namespace fahr::aist_bench
