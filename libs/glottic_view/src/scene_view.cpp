// The scene's bodies as the glottic view's occluders.
#include "fahr/glottic_view/scene_view.h"

#include <stdexcept>
#include <utility>

#include "fahr/geometry/surface_loader.h"
#include "fahr/geometry/tet_mesh_loader.h"

namespace fahr::glottic_view {
namespace {

Opening opening_of(const scene::GlotticViewSettings& g) {
  return {g.opening_centre_m, g.opening_normal, g.opening_radius_m, g.opening_major_axis,
          g.opening_minor_radius_m};
}

geometry::SurfaceMesh posed(const geometry::SurfaceMesh& local, const scene::Pose& pose) {
  std::vector<Eigen::Vector3d> world;
  world.reserve(local.vertex_count());
  for (const auto& v : local.vertices()) world.push_back(pose.position_m + pose.orientation * v);
  return {std::move(world), local.triangles()};
}

}  // namespace

SceneGlotticView glottic_view_from_scene(const scene::Scene& scene, std::size_t samples) {
  if (!scene.glottic_view) {
    throw std::invalid_argument(scene.source_name + ": the scene has no glottic_view section");
  }
  SceneGlotticView out{GlotticView(opening_of(*scene.glottic_view), samples),
                       scene.glottic_view->eye_in_tool_m,
                       scene.glottic_view->rate_hz,
                       {},
                       {},
                       {}};
  for (const scene::Body& body : scene.bodies) {
    switch (body.role) {
      case scene::BodyRole::kObstacle:
        out.view.add_rigid(
            posed(geometry::load_surface(body.mesh_path, body.mesh_scale), body.pose));
        break;
      case scene::BodyRole::kTool:
        out.view.set_tool(geometry::load_surface(body.mesh_path, body.mesh_scale));
        break;
      case scene::BodyRole::kDeformable: {
        const geometry::TetMesh local = geometry::load_tet_mesh(body.mesh_path, body.mesh_scale);
        std::vector<geometry::Triangle> boundary;
        boundary.reserve(local.boundary_faces().size());
        for (const auto& f : local.boundary_faces()) boundary.push_back(f.nodes);
        out.view.add_deformable(std::move(boundary));
        std::vector<Eigen::Vector3d> rest;
        rest.reserve(local.node_count());
        for (const auto& p : local.rest_positions())
          rest.push_back(body.pose.position_m + body.pose.orientation * p);
        out.deformable_body_ids.push_back(body.id);
        out.deformable_node_counts.push_back(local.node_count());
        out.deformable_rest_m.push_back(std::move(rest));
        break;
      }
    }
  }
  return out;
}

}  // namespace fahr::glottic_view
