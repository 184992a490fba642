// The glottic view counted in pixels: the scene rendered from the eye by
// tools/scene_render's rasterizer with the opening as a disc of its own id,
// the disc's visible samples over those it has drawn alone. An independent
// check of fahr::glottic_view's ray-cast score (a z-buffer instead of
// lines of sight, polygons instead of a sampled disc), and the pictures.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fahr/glottic_view/glottic_view.h"
#include "fahr/scene/scene.h"
#include "fahr/scenegen/geometry_types.h"

namespace fahr::glottic_score {

// The scene's bodies as the renderer draws them, mm.
struct SceneMeshes {
  struct Rigid {
    std::string name;
    scenegen::TriangleMesh mesh_mm;  // world frame
  };
  std::vector<Rigid> rigid;
  scenegen::TriangleMesh tool_mm;  // tool frame
  bool has_tool = false;
  std::vector<std::vector<std::array<int, 3>>> deformable_boundaries;
};

// Throws geometry::LoadError naming the file.
SceneMeshes load_scene_meshes(const scene::Scene& scene);

struct PixelShare {
  double visible_share = 0.0;
  std::size_t visible = 0;  // disc samples seen past everything
  std::size_t total = 0;    // disc samples drawn alone
};

struct ViewInput {
  Eigen::Vector3d eye_m = Eigen::Vector3d::Zero();
  std::optional<Eigen::Isometry3d> world_from_tool;
  // Per deformable body, its node positions, world frame, m.
  std::vector<std::span<const Eigen::Vector3d>> deformable_positions;
};

// The opening's visible share in a square view of `size_px` (supersampled
// `supersample` times) that the opening fills.
PixelShare pixel_share(const SceneMeshes& meshes, const glottic_view::Opening& opening,
                       const ViewInput& input, int size_px = 400, int supersample = 2);

// The laryngoscopist's picture: the eye looking at the opening with a
// `fov_deg` field of view, the opening drawn in green. Returns the error or "".
std::string write_view_png(const SceneMeshes& meshes, const glottic_view::Opening& opening,
                           const ViewInput& input, const std::string& path, int size_px = 600,
                           double fov_deg = 40.0);

}  // namespace fahr::glottic_score
