// A rigid tool against rigid anatomy: points sampled evenly on the tool's
// surface, grouped in a tree of bounding spheres, tested against the
// anatomy's signed distance field. The tool's contacts with the tongue come
// from the AIST (spheres inside the tissue); its contacts with the palate,
// jaw, lips and trachea come from here, so the proxy stops at bone instead of
// passing through it.
//
// The broad phase needs no tree on the anatomy: a signed distance field is
// 1-Lipschitz, so a node whose centre lies farther from the surface than its
// radius (plus the margin and the grid's error) cannot reach it. The narrow
// phase reads the field's grid only (~0.1 us a point): exact on flat faces,
// off by a fraction of a cell at edges, which a hard stop tolerates.
//
// Each leaf reports at most one contact, its deepest sample: a blade lying
// flat on the palate gives one row per few millimetres, not one per sample,
// which keeps the contact solve small. The leaf index is stable, so it keys
// the solver's warm start from tick to tick.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fahr/collision/rigid_body.h"
#include "fahr/geometry/surface_mesh.h"

namespace fahr::collision {

struct SurfaceSampleSettings {
  // At most one sample per cube of this side (the candidate nearest the
  // cube's centre), m, > 0. Candidates are the vertices and a lattice on
  // every triangle with edges longer than the spacing, so large flat faces
  // are sampled too.
  double spacing_m = 1.5e-3;
  // Samples per leaf, >= 1: one contact per leaf at most.
  int leaf_size = 8;
  // More samples than this are refused (a spacing far too fine for the tool).
  std::size_t max_samples = 200000;
};

struct SurfaceSampleNode {
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();  // tool frame, m
  double radius_m = 0.0;                               // bounds every sample below, m
  // Leaf: first sample and count; inner: left child (right = left + 1), count 0.
  std::int32_t first = 0;
  std::int32_t count = 0;
};

class SurfaceSamples {
 public:
  static constexpr int kMaxDepth = 64;  // traversal stack; median splits keep the depth ~log2(n)

  SurfaceSamples() = default;
  // Throws std::invalid_argument naming the setting for an empty surface,
  // bad settings or too many samples.
  SurfaceSamples(const geometry::SurfaceMesh& surface, const SurfaceSampleSettings& settings);

  // Tool frame, m, in leaf order.
  const std::vector<Eigen::Vector3d>& points_m() const { return points_m_; }
  const std::vector<SurfaceSampleNode>& nodes() const { return nodes_; }
  int depth() const { return depth_; }

 private:
  void build(std::int32_t node, std::int32_t begin, std::int32_t end, int depth, int leaf_size);

  std::vector<Eigen::Vector3d> points_m_;
  std::vector<SurfaceSampleNode> nodes_;
  int depth_ = 0;
};

// The tool touching (or within the margin of) a rigid body at one sample.
struct SurfaceContact {
  std::uint32_t sample = 0;   // index of the sample in points_m(): stable across ticks
  std::uint32_t body_id = 0;  // RigidBody::id
  Eigen::Vector3d tool_point_m = Eigen::Vector3d::Zero();     // the deepest sample, world frame
  Eigen::Vector3d surface_point_m = Eigen::Vector3d::Zero();  // nearest surface point, world frame
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();  // body's outward normal there, world frame
  double depth_m = 0.0;  // > 0 inside the body; in (-margin, 0] near it
};

struct SurfaceQueryStats {
  std::uint32_t nodes_visited = 0;
  std::uint32_t points_tested = 0;
  std::uint32_t contacts = 0;  // found, including those the buffer could not take
  bool overflowed = false;
};

// Appends to out[count..] the contacts of the tool at `world_from_tool` with
// `body`, one per sample with signed distance below margin_m. (One per leaf,
// its deepest sample, made a leaf's row jump between two samples whose
// normals differ, a lip's edge under the blade: one plane on one tick, the
// other on the next, the proxy hopping between them; a row per sample keeps
// both planes.) Allocation-free, noexcept.
SurfaceQueryStats query_surface_samples(const SurfaceSamples& samples,
                                        const Eigen::Isometry3d& world_from_tool,
                                        const RigidBody& body, double margin_m,
                                        std::span<SurfaceContact> out, std::size_t& count) noexcept;

}  // namespace fahr::collision
