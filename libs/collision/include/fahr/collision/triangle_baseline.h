// The baseline of the comparison (paper Figure 6): direct triangle-level
// collision between a deformable body's boundary triangles and a rigid tool's
// triangles. Broad phase: Bullet's GImpact box trees (btGImpactBvh), built
// once and refitted (never rebuilt) when the body deforms. Narrow phase: ours,
// vertex against face both ways, the same quantities the spheres give (point
// on the tool surface, normal from the tool toward the tissue, depth).
// Bullet is private to the implementation.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "fahr/geometry/surface_mesh.h"

namespace fahr::collision {

struct TriangleContact {
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();  // on the tool surface, world, m
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();  // from the tool toward the tissue, world
  double depth_m = 0.0;  // > 0 touching; in (-candidate margin, 0] a candidate (a gap), m
  std::int32_t tissue_vertex = -1;  // the penetrating tissue vertex, or -1
  std::int32_t tool_vertex = -1;    // the penetrating tool vertex, or -1
  // The tissue vertex the contact acts on: the penetrating one, or for a
  // tool vertex the nearest corner of the tissue face it is behind.
  std::int32_t acting_tissue_vertex = -1;
};

class TriangleBaseline {
 public:
  // tissue: the body's boundary surface at rest (world frame, m);
  // surface_to_node[i]: the FEM node of surface vertex i. tool: tool frame, m.
  // Throws std::invalid_argument for empty or mismatched input.
  TriangleBaseline(const geometry::SurfaceMesh& tissue,
                   std::vector<geometry::Index> surface_to_node, const geometry::SurfaceMesh& tool);
  ~TriangleBaseline();
  TriangleBaseline(const TriangleBaseline&) = delete;
  TriangleBaseline& operator=(const TriangleBaseline&) = delete;

  // Deformed node positions, 3 per node (m): moves the tissue vertices and
  // refits the tissue tree.
  void update(std::span<const double> positions_m);
  // Contacts with the tool at world_from_tool into `out` (cleared first).
  // candidate_margin_m, [0, kMaxFaceDepthM): vertices this close in front of
  // a face are reported too, as candidates (the AIST query's candidates: the
  // contact solve sees them before they touch). A vertex behind some face is
  // never reported as another face's candidate.
  void collide(const Eigen::Isometry3d& world_from_tool, std::vector<TriangleContact>& out,
               double candidate_margin_m = 0.0);

  std::uint64_t refit_count() const;
  std::uint64_t rebuild_count() const;  // builds after construction: stays 0

  // A vertex found behind a face deeper than this is not that face's contact
  // (it is another face's: a blade plate is 1.2 mm thick), m.
  static constexpr double kMaxFaceDepthM = 2e-3;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fahr::collision
