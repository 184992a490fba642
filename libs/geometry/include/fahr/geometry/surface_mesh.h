// A triangle surface: vertices (m), triangles, and what the signed distance
// needs of it: face normals, angle-weighted vertex pseudo-normals, edge
// pseudo-normals, and whether it is closed and manifold. Immutable once built.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <vector>

#include "fahr/geometry/mesh_types.h"

namespace fahr::geometry {

// Two unit normals whose sum is shorter than this are back to back: a wedge
// of 1e-6 rad is thinner than a nanometre per millimetre of width, which no
// tissue or instrument surface has; it is a fold of the mesh.
inline constexpr double kFoldedNormalSum = 1e-6;

// What the topology checks found; a closed, manifold, consistently oriented
// surface has every count zero.
struct SurfaceTopology {
  std::size_t boundary_edge_count = 0;        // edges used by one triangle (holes)
  std::size_t non_manifold_edge_count = 0;    // edges used by three or more triangles
  std::size_t inconsistent_edge_count = 0;    // edges two triangles traverse the same way
  std::size_t non_manifold_vertex_count = 0;  // vertices whose triangles form more than one fan
  std::size_t degenerate_triangle_count = 0;  // zero area or a repeated vertex
  // Edges whose two triangles lie back to back (anti-parallel normals): the
  // surface folds onto itself there with zero thickness, so inside and
  // outside, and the sign of a distance, are undefined near it.
  std::size_t folded_edge_count = 0;

  bool closed() const { return boundary_edge_count == 0; }
  bool folded() const { return folded_edge_count > 0; }
  bool manifold() const {
    return non_manifold_edge_count == 0 && inconsistent_edge_count == 0 &&
           non_manifold_vertex_count == 0;
  }
};

class SurfaceMesh {
 public:
  SurfaceMesh() = default;
  // Throws std::invalid_argument on an out-of-range index or a non-finite vertex.
  SurfaceMesh(std::vector<Eigen::Vector3d> vertices_m, std::vector<Triangle> triangles);

  const std::vector<Eigen::Vector3d>& vertices() const { return vertices_; }  // m
  const std::vector<Triangle>& triangles() const { return triangles_; }
  std::size_t vertex_count() const { return vertices_.size(); }
  std::size_t triangle_count() const { return triangles_.size(); }

  // Unit normal per triangle, (v1 - v0) x (v2 - v0) normalised; zero for a degenerate triangle.
  const std::vector<Eigen::Vector3d>& face_normals() const { return face_normals_; }
  // Angle-weighted vertex pseudo-normals (Thurmer and Wuthrich 1998; Baerentzen
  // and Aanaes 2005), unit length; zero for an unused vertex.
  const std::vector<Eigen::Vector3d>& vertex_normals() const { return vertex_normals_; }
  // Edge pseudo-normal per triangle edge k = (v_k, v_{k+1 mod 3}): the sum of
  // the normals of the triangles sharing it, unit length. An edge used by one
  // triangle gets that triangle's normal.
  const std::vector<std::array<Eigen::Vector3d, 3>>& edge_normals() const { return edge_normals_; }

  const SurfaceTopology& topology() const { return topology_; }
  bool is_closed() const { return topology_.closed(); }
  bool is_manifold() const { return topology_.manifold(); }

  Eigen::Vector3d bounds_min() const { return bounds_min_; }  // m
  Eigen::Vector3d bounds_max() const { return bounds_max_; }  // m
  // Enclosed volume (m^3) by the divergence theorem; meaningful for a closed, outward-oriented
  // surface.
  double enclosed_volume_m3() const;

 private:
  void compute_normals_and_topology();

  std::vector<Eigen::Vector3d> vertices_;
  std::vector<Triangle> triangles_;
  std::vector<Eigen::Vector3d> face_normals_;
  std::vector<Eigen::Vector3d> vertex_normals_;
  std::vector<std::array<Eigen::Vector3d, 3>> edge_normals_;
  SurfaceTopology topology_;
  Eigen::Vector3d bounds_min_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d bounds_max_ = Eigen::Vector3d::Zero();
};

}  // namespace fahr::geometry
