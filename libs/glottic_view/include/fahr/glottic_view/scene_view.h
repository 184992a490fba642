// A GlotticView built from a scene's `glottic_view` section and its bodies:
// obstacles as rigid occluders, the tool's surface, each deformable body's
// boundary.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fahr/glottic_view/glottic_view.h"
#include "fahr/scene/scene.h"

namespace fahr::glottic_view {

struct SceneGlotticView {
  GlotticView view;
  Eigen::Vector3d eye_in_tool_m = Eigen::Vector3d::Zero();
  double rate_hz = 10.0;
  // Deformable bodies in the view's order: their ids and node counts.
  std::vector<std::uint32_t> deformable_body_ids;
  std::vector<std::size_t> deformable_node_counts;
  // Their rest node positions, world frame, m (the view at rest).
  std::vector<std::vector<Eigen::Vector3d>> deformable_rest_m;
};

// Throws std::invalid_argument when the scene has no glottic_view section,
// geometry::LoadError naming the file when a mesh cannot be read.
SceneGlotticView glottic_view_from_scene(const scene::Scene& scene, std::size_t samples = 1024);

}  // namespace fahr::glottic_view
