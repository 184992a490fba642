// SceneDescription from the haptic service's set-up.
#include "fahr/haptic_service/scene_publication.h"

#include <algorithm>

namespace fahr::haptic_service {
namespace {

msg::BodyRole wire_role(scene::BodyRole role) {
  switch (role) {
    case scene::BodyRole::kDeformable:
      return msg::BODY_DEFORMABLE;
    case scene::BodyRole::kTool:
      return msg::BODY_TOOL;
    case scene::BodyRole::kObstacle:
      break;
  }
  return msg::BODY_OBSTACLE;
}

void describe_deformable(const TissueBody& body, msg::SceneDescription& d) {
  for (const auto& p : body.mesh.rest_positions()) {
    for (int k = 0; k < 3; ++k) d.rest_positions_m().push_back(static_cast<float>(p[k]));
  }
  for (const auto& t : body.mesh.tets()) {
    for (auto n : t) d.tets().push_back(static_cast<std::uint32_t>(n));
  }
  for (const auto& f : body.mesh.boundary_faces()) {
    for (auto n : f.nodes) d.triangles().push_back(static_cast<std::uint32_t>(n));
  }
  const auto& layout = body.layout;
  d.layout_fingerprint(layout.fingerprint());
  for (std::size_t i = 0; i < layout.size(); ++i) {
    const auto& s = layout.sphere(i);
    for (int k = 0; k < 3; ++k) d.sphere_rest_m().push_back(static_cast<float>(s.rest_centre_m[k]));
    d.sphere_rest_m().push_back(static_cast<float>(s.rest_radius_m));
    d.sphere_link_offsets().push_back(static_cast<std::uint32_t>(d.sphere_nodes().size()));
    for (auto n : layout.nodes(i)) d.sphere_nodes().push_back(n);
    for (auto w : layout.weights(i)) d.sphere_weights().push_back(static_cast<float>(w));
    d.sphere_levels().push_back(s.origin == sphere_layout::SphereOrigin::kHugging ? 255 : s.level);
  }
}

}  // namespace

std::vector<msg::SceneDescription> describe_scene(const HapticSetup& setup) {
  const scene::Scene& scene = *setup.scene;
  std::vector<msg::SceneDescription> out;
  const std::size_t text_bytes =
      std::min<std::size_t>(scene.source_text.size(), msg::MAX_SCENE_TEXT);
  for (const auto& body : scene.bodies) {
    msg::SceneDescription d;
    d.body_id(body.id);
    d.body_count(static_cast<std::uint32_t>(scene.bodies.size()));
    d.scene_name(scene.name);
    d.body_name(body.name);
    d.role(wire_role(body.role));
    d.mesh_uri(body.mesh_uri.substr(0, 255));
    d.scene_text_utf8().assign(scene.source_text.begin(),
                               scene.source_text.begin() + static_cast<std::ptrdiff_t>(text_bytes));
    for (const TissueBody& tissue : setup.bodies) {
      if (tissue.body == &body) describe_deformable(tissue, d);
    }
    out.push_back(std::move(d));
  }
  return out;
}

}  // namespace fahr::haptic_service
