// World-frame meshes and AIST settings of scene bodies.
#include "fahr/runtime/scene_bodies.h"

#include <vector>

#include "fahr/geometry/tet_mesh_loader.h"

namespace fahr::runtime {

geometry::TetMesh world_tet_mesh(const scene::Body& body) {
  const geometry::TetMesh local = geometry::load_tet_mesh(body.mesh_path, body.mesh_scale);
  std::vector<Eigen::Vector3d> world;
  world.reserve(local.node_count());
  for (const auto& p : local.rest_positions())
    world.push_back(body.pose.position_m + body.pose.orientation * p);
  return geometry::TetMesh(std::move(world), local.tets());
}

sphere_layout::FillSettings fill_settings_for(const scene::Body& body) {
  sphere_layout::FillSettings f;
  const auto& a = body.deformable->aist;
  f.volume_ratio = a.sphere_tet_volume_ratio;
  f.refinement_levels = a.refinement_levels;
  f.surface_hugging = a.surface_spheres;
  f.max_spheres = static_cast<std::size_t>(a.sphere_budget);
  // The services' rows use the sphere's own depth (the FEM projects whole
  // spheres), so the surface anchors would only cost the digest a gather
  // per FEM state.
  f.surface_anchors = false;
  return f;
}

}  // namespace fahr::runtime
