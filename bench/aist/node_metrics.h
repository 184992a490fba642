// Detection judged against the geometry itself rather than against the other
// detector: the ground truth of a state is the set of tongue surface nodes
// inside the blade (the blade's field, exact near its surface). Each such node
// is recalled by the AIST when a sphere reporting contact holds it within
// its radius + ContactMetrics::kRegionSlackM, and by the baseline when it
// reports that vertex. The depth error is, per such node, the exact
// penetration against the deepest such sphere's depth (0 when none) and the
// baseline's depth of that vertex (0 when not reported).
#pragma once

#include <Eigen/Geometry>
#include <span>
#include <vector>

#include "fahr/collision/contact_buffer.h"
#include "fahr/collision/sphere_state.h"
#include "fahr/collision/triangle_baseline.h"
#include "scene.h"

namespace fahr::aist_bench {

class NodeMetrics {
 public:
  explicit NodeMetrics(const Scene& scene);
  void add_tick(const collision::ContactBuffer& aist, const collision::SphereState& state,
                const std::vector<collision::TriangleContact>& base,
                const Eigen::Isometry3d& world_from_blade, std::span<const double> positions_m);
  void print() const;

 private:
  // Depth classes, m: all, and the two of ContactMetrics.
  static constexpr int kClasses = 3;
  static constexpr double kClassDepthM[kClasses] = {0.0, 0.1e-3, 0.25e-3};

  const Scene& scene_;
  std::vector<std::uint32_t> nodes_;          // boundary nodes, unique
  std::vector<std::int32_t> node_to_vertex_;  // per node: a boundary vertex or -1
  std::vector<std::uint32_t> base_stamp_;     // per boundary vertex: tick it was reported
  std::vector<double> base_depth_m_;          // per boundary vertex, valid when stamped
  std::uint32_t tick_ = 0;
  std::size_t total_[kClasses] = {}, aist_[kClasses] = {}, aist_near_[kClasses] = {},
              base_[kClasses] = {};
  std::size_t miss_candidate_ = 0, miss_standoff_ = 0, miss_detached_ = 0;
  std::vector<double> exact_m_, aist_error_m_, aist_signed_error_m_, base_error_m_;
  std::vector<double> recalled_error_m_;  // AIST error over recalled nodes only
  // The surface depth of the reporting sphere holding the node whose surface
  // point is nearest it (SphereContact::surface_depth_m; 0 when none).
  std::vector<double> surface_error_m_;
};

}  // namespace fahr::aist_bench
