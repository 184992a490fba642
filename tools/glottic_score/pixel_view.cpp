// Pixel counts and pictures of the glottic view.
#include "pixel_view.h"

#include <cmath>

#include "fahr/geometry/surface_loader.h"
#include "fahr/geometry/tet_mesh_loader.h"
#include "png_writer.h"
#include "rasterizer.h"

namespace fahr::glottic_score {
namespace {

using scenegen::TriangleMesh;
using scenegen::Vec3;

constexpr int kDiscId = 1;
constexpr int kDiscSegments = 256;
constexpr double kPi = 3.14159265358979323846;

TriangleMesh to_mm(const geometry::SurfaceMesh& s, const scene::Pose* pose) {
  TriangleMesh m;
  m.vertices.reserve(s.vertex_count());
  for (const auto& v : s.vertices()) {
    const Eigen::Vector3d w = pose ? Eigen::Vector3d(pose->position_m + pose->orientation * v) : v;
    m.vertices.push_back(1e3 * w);
  }
  for (const auto& t : s.triangles()) m.triangles.push_back({t[0], t[1], t[2]});
  return m;
}

TriangleMesh disc_mm(const glottic_view::Opening& o) {
  TriangleMesh m;
  m.vertices.push_back(1e3 * o.centre_m);
  for (int i = 0; i < kDiscSegments; ++i) {
    const double a = 2.0 * kPi * i / kDiscSegments;
    m.vertices.push_back(1e3 * glottic_view::opening_point(o, std::cos(a), std::sin(a)));
    m.triangles.push_back({0, 1 + i, 1 + (i + 1) % kDiscSegments});
  }
  return m;
}

TriangleMesh posed_tool(const SceneMeshes& meshes, const Eigen::Isometry3d& world_from_tool) {
  TriangleMesh m = meshes.tool_mm;
  for (auto& v : m.vertices) v = 1e3 * (world_from_tool * (1e-3 * v));
  return m;
}

TriangleMesh deformed(const std::vector<std::array<int, 3>>& boundary,
                      std::span<const Eigen::Vector3d> positions_m) {
  TriangleMesh m;
  m.vertices.reserve(positions_m.size());
  for (const auto& p : positions_m) m.vertices.push_back(1e3 * p);
  m.triangles = boundary;
  return m;
}

// Draws everything but the opening, all with id 0.
void draw_occluders(scene_render::Rasterizer& r, const SceneMeshes& meshes, const ViewInput& in) {
  for (const auto& body : meshes.rigid) {
    const Vec3 colour = body.name.find("larynx") != std::string::npos ? Vec3(0.45, 0.60, 0.90)
                        : body.name.find("lip") != std::string::npos  ? Vec3(0.96, 0.76, 0.66)
                                                                      : Vec3(0.90, 0.85, 0.70);
    r.draw(body.mesh_mm, colour, 0);
  }
  for (std::size_t b = 0;
       b < meshes.deformable_boundaries.size() && b < in.deformable_positions.size(); ++b) {
    r.draw(deformed(meshes.deformable_boundaries[b], in.deformable_positions[b]),
           Vec3(0.85, 0.38, 0.42), 0);
  }
  if (meshes.has_tool && in.world_from_tool) {
    r.draw(posed_tool(meshes, *in.world_from_tool), Vec3(0.72, 0.74, 0.78), 0);
  }
}

scene_render::Camera eye_camera(const glottic_view::Opening& o, const Eigen::Vector3d& eye_m,
                                double fov_deg) {
  scene_render::Camera c;
  c.perspective = true;
  c.eye_mm = 1e3 * eye_m;
  c.centre_mm = 1e3 * o.centre_m;
  c.fov_deg = fov_deg;
  // Up: the opening's normal, unless the eye looks along it.
  const Eigen::Vector3d forward = (o.centre_m - eye_m).normalized();
  c.up = std::abs(forward.dot(o.normal)) < 0.99 ? o.normal : o.normal.unitOrthogonal();
  c.eye_direction = -forward;
  c.width_mm = 1.0;
  return c;
}

}  // namespace

SceneMeshes load_scene_meshes(const scene::Scene& scene) {
  SceneMeshes out;
  for (const scene::Body& body : scene.bodies) {
    switch (body.role) {
      case scene::BodyRole::kObstacle:
        out.rigid.push_back(
            {body.name,
             to_mm(geometry::load_surface(body.mesh_path, body.mesh_scale), &body.pose)});
        break;
      case scene::BodyRole::kTool:
        out.tool_mm = to_mm(geometry::load_surface(body.mesh_path, body.mesh_scale), nullptr);
        out.has_tool = true;
        break;
      case scene::BodyRole::kDeformable: {
        const geometry::TetMesh mesh = geometry::load_tet_mesh(body.mesh_path, body.mesh_scale);
        std::vector<std::array<int, 3>> boundary;
        for (const auto& f : mesh.boundary_faces())
          boundary.push_back({f.nodes[0], f.nodes[1], f.nodes[2]});
        out.deformable_boundaries.push_back(std::move(boundary));
        break;
      }
    }
  }
  return out;
}

PixelShare pixel_share(const SceneMeshes& meshes, const glottic_view::Opening& opening,
                       const ViewInput& input, int size_px, int supersample) {
  PixelShare out;
  const double distance = (input.eye_m - opening.centre_m).norm();
  if ((input.eye_m - opening.centre_m).dot(opening.normal) <= 0.0 || distance <= 0.0) return out;
  // The disc fills about 80 % of the view's width.
  const double fov_deg = 2.0 * std::atan(1.25 * opening.radius_m / distance) * 180.0 / kPi;
  const scene_render::Camera camera = eye_camera(opening, input.eye_m, fov_deg);
  const TriangleMesh disc = disc_mm(opening);
  scene_render::Rasterizer alone(size_px, size_px, supersample, camera, {});
  alone.draw(disc, Vec3(0.0, 1.0, 0.0), kDiscId);
  out.total = alone.count(kDiscId);
  scene_render::Rasterizer all(size_px, size_px, supersample, camera, {});
  draw_occluders(all, meshes, input);
  all.draw(disc, Vec3(0.0, 1.0, 0.0), kDiscId);
  out.visible = all.count(kDiscId);
  out.visible_share =
      out.total > 0 ? static_cast<double>(out.visible) / static_cast<double>(out.total) : 0.0;
  return out;
}

std::string write_view_png(const SceneMeshes& meshes, const glottic_view::Opening& opening,
                           const ViewInput& input, const std::string& path, int size_px,
                           double fov_deg) {
  scene_render::Rasterizer r(size_px, size_px, 2, eye_camera(opening, input.eye_m, fov_deg), {});
  draw_occluders(r, meshes, input);
  r.draw(disc_mm(opening), Vec3(0.1, 0.85, 0.2), kDiscId);
  std::string error;
  if (!scene_render::write_png(path, size_px, size_px, r.resolve(), error)) return error;
  return "";
}

}  // namespace fahr::glottic_score
