// The neonatal scene as the benchmark uses it: tongue (m), its fixed nodes,
// the Miller 1 blade and its field, the scripted laryngoscope trajectory and
// the FEM body.
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <string>
#include <vector>

#include "fahr/fem/body.h"
#include "fahr/geometry/signed_distance_field.h"
#include "fahr/geometry/surface_mesh.h"
#include "fahr/geometry/tet_mesh.h"

namespace fahr::aist_bench {

struct Scene {
  geometry::TetMesh tongue;  // m
  std::vector<std::uint32_t> fixed_nodes;
  geometry::SurfaceMesh boundary;  // tongue boundary, m
  std::vector<geometry::Index> surface_to_node;
  geometry::SignedDistanceField boundary_sdf;
  geometry::SurfaceMesh blade;  // Miller 1, tool frame, m
  geometry::SignedDistanceField blade_sdf;
  double mean_boundary_edge_m = 0.0;
  // Height (y, m) of the rest dorsum near the mid-line per 1 mm bin of x,
  // from dorsum_x0_m on; -inf where the tongue is absent.
  std::vector<double> dorsum_y_m;
  double dorsum_x0_m = 0.0;
};

// Loads the neonatal scene from `dir` (meshes/neonatal, or a scene that
// tools/scene_generator wrote elsewhere, e.g. a finer tongue); the blade's
// field has `blade_cell_m` cells.
std::unique_ptr<Scene> load_scene(double blade_cell_m, const std::string& dir);

// The scripted trajectory, s in [0, 1]. meshes/neonatal/README.md's initial pose (tip
// (12, 0.5, 0) mm) and pressing pose (tip x -33 mm, pitch 8 deg) set where it
// starts and ends; that README's pressing height cuts 5 mm into the rest
// tongue, so the blade is instead slid in at pitch 0 -> 8 deg with its
// underside 0.2 mm above the rest dorsum (first 50%), then pressed down by
// lever_depth_m (to 80%), then levered: pitch up 4 deg more about the tip
// while the tip sinks 1 mm more (the rest).
Eigen::Isometry3d blade_pose(const Scene& scene, double s, double lever_depth_m);

// The FEM body of the tongue: gravity -x (supine), CHOLMOD on the rest matrix
// (factorised once) so a step costs a solve, not a factorisation.
std::unique_ptr<fem::Body> make_tongue_body(const Scene& scene);

}  // namespace fahr::aist_bench
