// Scene -> AIST, rigid fields and response settings of the haptic service.
#include "fahr/haptic_service/haptic_setup.h"

#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>

#include "fahr/runtime/scene_bodies.h"
#include "fahr/scene/plan.h"
#include "fahr/sphere_layout/fill_spheres.h"

namespace fahr::haptic_service {
namespace {

contact::ResponseSettings response_settings(const scene::Scene& scene) {
  contact::ResponseSettings s;
  s.mode = contact::ResponseMode::kCompliance;
  s.coupling.stiffness_npm = scene.contact.coupling_stiffness_npm;
  s.coupling.damping_nspm = scene.contact.coupling_damping_nspm;
  s.force_aware.hysteresis = scene.contact.force_aware_hysteresis;
  s.force_aware.held_proxy = scene.contact.held_proxy == scene::HeldProxy::kStay
                                 ? contact::HeldProxy::kStay
                                 : contact::HeldProxy::kHoldLoad;
  // The DeformationState carries W for at most 64 spheres: more rows would
  // all run on the fallback compliance.
  // Tissue rows are bounded by W (64 spheres); the anatomy adds its own.
  s.max_rows = 64 + 16;
  s.max_contacts = 512;  // msg::MAX_CONTACTS
  s.max_holds = 64;
  return s;
}

}  // namespace

std::unique_ptr<TriangleCollisionSetup> triangle_setup(const HapticSetup& setup) {
  auto t = std::make_unique<TriangleCollisionSetup>();
  t->boundary = setup.mesh.boundary_surface(&t->surface_to_node);
  // Nearest rest sphere per boundary vertex: a one-off O(vertices x
  // spheres) scan (~10 M distances on the neonatal tongue, tens of ms).
  const auto& spheres = setup.layout.spheres();
  t->vertex_sphere.resize(t->boundary.vertex_count());
  for (std::size_t v = 0; v < t->boundary.vertex_count(); ++v) {
    const Eigen::Vector3d& x = t->boundary.vertices()[v];
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t s = 0; s < spheres.size(); ++s) {
      const double d = (spheres[s].rest_centre_m - x).squaredNorm();
      if (d < best) {
        best = d;
        t->vertex_sphere[v] = static_cast<std::uint32_t>(s);
      }
    }
  }
  return t;
}

HapticSetup set_up(const scene::Scene& scene, CollisionMethod collision, bool fem_keeps_anatomy) {
  const scene::ServicePlan plan = scene::derive_plan(scene);
  if (!plan.tool_body)
    throw std::runtime_error("scene '" + scene.name +
                             "' has no tool: nothing for the haptic service");
  if (plan.fem_bodies.size() != 1) {
    throw std::runtime_error("scene '" + scene.name + "' has " +
                             std::to_string(plan.fem_bodies.size()) +
                             " deformable bodies; this service handles exactly one");
  }
  HapticSetup setup;
  setup.scene = &scene;
  setup.deformable = &scene.bodies[plan.fem_bodies.front()];
  setup.mesh = runtime::world_tet_mesh(*setup.deformable);
  // W along the normals covers every row the FEM was sent last: rows by
  // their free-motion depth keep them (RowCompliance::kFreeDepth).
  if (scene.solver.compliance_columns == scene::ComplianceColumns::kNormals) {
    setup.row_compliance = RowCompliance::kFreeDepth;
  }
  try {
    setup.layout =
        sphere_layout::fill_spheres(setup.mesh, runtime::fill_settings_for(*setup.deformable));
  } catch (const std::exception& e) {
    throw std::runtime_error("body '" + setup.deformable->name + "': AIST: " + e.what());
  }
  setup.tool = runtime::load_rigid_field(scene.bodies[*plan.tool_body]);
  setup.tool_grid = std::make_unique<collision::FieldGrid>(*setup.tool->sdf);
  try {
    setup.tool_samples =
        collision::SurfaceSamples(setup.tool->surface, collision::SurfaceSampleSettings{});
  } catch (const std::exception& e) {
    throw std::runtime_error("body '" + setup.tool->scene_body->name +
                             "': surface samples: " + e.what());
  }
  // Each anatomy body is loaded once, whichever pairs name it.
  std::vector<std::size_t> anatomy_of_body(scene.bodies.size(), SIZE_MAX);
  const auto anatomy_index = [&](std::size_t body) {
    if (anatomy_of_body[body] == SIZE_MAX) {
      anatomy_of_body[body] = setup.anatomy.size();
      setup.anatomy.push_back(runtime::load_rigid_field(scene.bodies[body]));
    }
    return anatomy_of_body[body];
  };
  for (const auto& pair : plan.pairs) {
    if (pair.kind == scene::PairKind::kHard && pair.first == plan.fem_bodies.front()) {
      if (fem_keeps_anatomy) continue;
      setup.tissue_obstacles.push_back(anatomy_index(pair.second));
    } else if (pair.kind == scene::PairKind::kTool &&
               pair.reason == scene::PairReason::kToolObstacle &&
               scene.contact.tool_stops_at_anatomy) {
      setup.tool_obstacles.push_back(anatomy_index(pair.second));
    }
  }
  setup.response = response_settings(scene);
  setup.penalty = scene.contact.response == scene::ContactResponse::kPenalty;
  setup.penalty_settings.stiffness_npm = scene.contact.penalty_stiffness_npm;
  setup.penalty_settings.max_rows = setup.response.max_rows;
  setup.collision = collision;
  if (collision == CollisionMethod::kTriangle) setup.triangles = triangle_setup(setup);
  return setup;
}

}  // namespace fahr::haptic_service
