// Scene -> AIST, rigid fields and response settings of the haptic service.
#include "haptic_setup.h"

#include <stdexcept>
#include <string>

#include "fahr/geometry/surface_loader.h"
#include "fahr/haptic/fill_spheres.h"
#include "fahr/runtime/scene_bodies.h"
#include "fahr/scene/plan.h"

namespace fahr::haptic_service {
namespace {

std::unique_ptr<RigidField> rigid_field(const scene::Body& body) {
  auto field = std::make_unique<RigidField>();
  field->scene_body = &body;
  field->surface = geometry::load_surface(body.mesh_path, body.mesh_scale);
  geometry::SdfOptions options;
  options.cell_size_m = body.rigid ? body.rigid->sdf_cell_m : options.cell_size_m;
  try {
    field->sdf = std::make_unique<geometry::SignedDistanceField>(field->surface, options);
  } catch (const std::exception& e) {
    throw std::runtime_error("body '" + body.name + "' (" + body.mesh_path.string() + "): signed distance field: " +
                             e.what());
  }
  return field;
}

contact::ResponseSettings response_settings(const scene::Scene& scene) {
  if (scene.contact.response != scene::ContactResponse::kForceAware) {
    throw std::runtime_error("contact.response '" + std::string(scene::to_string(scene.contact.response)) +
                             "': fahr_haptic_service runs force_aware only (the penalty baseline is in "
                             "tools/contact_bench)");
  }
  contact::ResponseSettings s;
  s.mode = contact::ResponseMode::kCompliance;
  s.coupling.stiffness_npm = scene.contact.coupling_stiffness_npm;
  s.coupling.damping_nspm = scene.contact.coupling_damping_nspm;
  s.force_aware.hysteresis = scene.contact.force_aware_hysteresis;
  // The DeformationState carries W for at most 64 spheres: more rows would
  // all run on the fallback compliance.
  s.max_rows = 64;
  s.max_contacts = 512;  // msg::MAX_CONTACTS
  s.max_holds = 64;
  return s;
}

}  // namespace

HapticSetup set_up(const scene::Scene& scene) {
  const scene::ServicePlan plan = scene::derive_plan(scene);
  if (!plan.tool_body) throw std::runtime_error("scene '" + scene.name + "' has no tool: nothing for the haptic service");
  if (plan.fem_bodies.size() != 1) {
    throw std::runtime_error("scene '" + scene.name + "' has " + std::to_string(plan.fem_bodies.size()) +
                             " deformable bodies; this service handles exactly one");
  }
  HapticSetup setup;
  setup.scene = &scene;
  setup.deformable = &scene.bodies[plan.fem_bodies.front()];
  setup.mesh = runtime::world_tet_mesh(*setup.deformable);
  try {
    setup.layout = haptic::fill_spheres(setup.mesh, runtime::fill_settings_for(*setup.deformable));
  } catch (const std::exception& e) {
    throw std::runtime_error("body '" + setup.deformable->name + "': AIST: " + e.what());
  }
  setup.tool = rigid_field(scene.bodies[*plan.tool_body]);
  for (const auto& pair : plan.pairs) {
    if (pair.kind != scene::PairKind::kHard || pair.first != plan.fem_bodies.front()) continue;
    setup.obstacles.push_back(rigid_field(scene.bodies[pair.second]));
  }
  setup.response = response_settings(scene);
  return setup;
}

}  // namespace fahr::haptic_service
