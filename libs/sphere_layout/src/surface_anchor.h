// The point of a boundary face nearest a sphere's centre, as weights of the
// face's nodes (internal): the hugging spheres' tangent point, which ties
// them to the surface (TetLinker::link_anchored), and every near-surface
// sphere's SurfaceAnchor. Header-only: used by the filling alone.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

#include "fahr/geometry/signed_distance_field.h"
#include "fahr/geometry/surface_mesh.h"
#include "fahr/sphere_layout/sphere_layout.h"

namespace fahr::sphere_layout::detail {

// The nearest point of `boundary` (the field's surface) to `centre_m` within
// `reach_m` (m; +infinity: anywhere), as a SurfaceAnchor whose nodes are the
// tet mesh's (surface_to_node). False when none lies within the reach or the
// face is degenerate.
inline bool nearest_face_point(const geometry::SurfaceMesh& boundary,
                               const std::vector<geometry::Index>& surface_to_node,
                               const geometry::SignedDistanceField& sdf,
                               const Eigen::Vector3d& centre_m, double reach_m,
                               SurfaceAnchor& out) {
  const double reach_squared = std::isinf(reach_m) ? reach_m : reach_m * reach_m;
  const geometry::BvhClosestPoint hit = sdf.bvh().closest_point(centre_m, reach_squared);
  if (hit.triangle < 0) return false;
  const geometry::Triangle& t = boundary.triangles()[static_cast<std::size_t>(hit.triangle)];
  const auto& v = boundary.vertices();
  // Barycentric coordinates of the hit in its triangle (areas of the sub-triangles).
  const Eigen::Vector3d n = (v[t[1]] - v[t[0]]).cross(v[t[2]] - v[t[0]]);
  const double area2 = n.squaredNorm();
  if (!(area2 > 0.0)) return false;
  Eigen::Vector3d bary;
  for (int k = 0; k < 3; ++k) {
    bary[k] = n.dot((v[t[(k + 1) % 3]] - hit.point).cross(v[t[(k + 2) % 3]] - hit.point)) / area2;
  }
  // The hit is on the triangle: only rounding can make a coordinate negative.
  bary = bary.cwiseMax(0.0);
  bary /= bary.sum();
  out.rest_point_m = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k) {
    const auto vertex = static_cast<std::size_t>(t[k]);
    out.nodes[static_cast<std::size_t>(k)] = static_cast<std::uint32_t>(surface_to_node[vertex]);
    out.weights[static_cast<std::size_t>(k)] = bary[k];
    out.rest_face_m[static_cast<std::size_t>(k)] = v[vertex];
    out.rest_point_m += bary[k] * v[vertex];
  }
  return true;
}

}  // namespace fahr::sphere_layout::detail
