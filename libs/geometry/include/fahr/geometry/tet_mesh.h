// The rest state of a tetrahedral body: rest positions, tets, outward
// boundary faces, per-tet volumes and quality statistics, all computed
// once. Per-step state (deformed positions, velocities) lives with whoever
// simulates the body, never here.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "fahr/geometry/mesh_types.h"
#include "fahr/geometry/surface_mesh.h"
#include "fahr/geometry/tet_quality.h"

namespace fahr::geometry {

// Rest data of one tet, computed once. No Dm^-1: the FEM keeps its own
// (fem::ElementRest), and set-up code that needs one at rest takes
// edge_matrix(...).inverse() (tet_deformation.h).
struct TetRestData {
  double volume_m3 = 0.0;  // > 0
};

// A boundary face, counter-clockwise seen from outside, and the tet it belongs to.
struct BoundaryFace {
  Triangle nodes{};
  Index tet = 0;
  int marker = 0;  // boundary marker from the source file (TetGen .face); 0 when none
};

class TetMesh {
 public:
  TetMesh() = default;
  // Throws std::invalid_argument for an out-of-range index, a non-finite
  // position, a tet of non-positive (or flat) volume, or a face shared by more
  // than two tets. Loaders check the same first, to name file and line.
  TetMesh(std::vector<Eigen::Vector3d> rest_positions_m, std::vector<Tet> tets);

  const std::vector<Eigen::Vector3d>& rest_positions() const { return rest_positions_; }  // m
  const std::vector<Tet>& tets() const { return tets_; }
  const std::vector<BoundaryFace>& boundary_faces() const { return boundary_faces_; }
  const std::vector<TetRestData>& rest_data() const { return rest_data_; }
  const TetQualityStats& quality() const { return quality_; }
  std::size_t node_count() const { return rest_positions_.size(); }
  std::size_t tet_count() const { return tets_.size(); }

  // Attaches boundary markers, e.g. from a TetGen .face file: markers[i] goes to
  // the boundary face with the same three nodes (any order) as faces[i].
  // Returns how many of the given faces are not boundary faces (interior
  // faces some TetGen switches also write); those are ignored.
  std::size_t assign_boundary_markers(const std::vector<Triangle>& faces,
                                      const std::vector<int>& markers);

  // The boundary as a surface over the boundary nodes only; surface vertex i
  // is tet-mesh node surface_to_node[i].
  SurfaceMesh boundary_surface(std::vector<Index>* surface_to_node = nullptr) const;

 private:
  void compute_rest_data();
  void compute_boundary();

  std::vector<Eigen::Vector3d> rest_positions_{};
  std::vector<Tet> tets_{};
  std::vector<BoundaryFace> boundary_faces_{};
  std::vector<TetRestData> rest_data_{};
  TetQualityStats quality_;
};

}  // namespace fahr::geometry
