// Scene -> AIST, rigid fields and response settings of the haptic service.
#include "fahr/haptic_service/haptic_setup.h"

#include <algorithm>
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

std::size_t body_of_sphere(const HapticSetup& setup, std::uint32_t sphere) {
  std::size_t b = 0;
  while (b + 1 < setup.bodies.size() && sphere >= setup.bodies[b + 1].first_sphere) ++b;
  return b;
}

std::vector<std::uint32_t> body_ids(const HapticSetup& setup) {
  std::vector<std::uint32_t> ids;
  for (const TissueBody& body : setup.bodies) ids.push_back(body.body->id);
  return ids;
}

HapticSetup set_up(const scene::Scene& scene, CollisionMethod collision, bool fem_keeps_anatomy) {
  const scene::ServicePlan plan = scene::derive_plan(scene);
  if (!plan.tool_body)
    throw std::runtime_error("scene '" + scene.name +
                             "' has no tool: nothing for the haptic service");
  if (plan.fem_bodies.empty())
    throw std::runtime_error("scene '" + scene.name +
                             "' has no deformable body: nothing for the haptic service");
  if (plan.fem_bodies.size() > kMaxTissueBodies)
    throw std::runtime_error(
        "scene '" + scene.name + "' has " + std::to_string(plan.fem_bodies.size()) +
        " deformable bodies; the haptic service takes at most " + std::to_string(kMaxTissueBodies));
  HapticSetup setup;
  setup.scene = &scene;
  std::size_t nodes = 0;
  std::uint32_t spheres = 0;
  for (const std::size_t index : plan.fem_bodies) {
    TissueBody body;
    body.body = &scene.bodies[index];
    body.mesh = runtime::world_tet_mesh(*body.body);
    try {
      body.layout = sphere_layout::fill_spheres(body.mesh, runtime::fill_settings_for(*body.body));
    } catch (const std::exception& e) {
      throw std::runtime_error("body '" + body.body->name + "': AIST: " + e.what());
    }
    body.layout_fingerprint = body.layout.fingerprint();
    body.first_node = nodes;
    body.first_sphere = spheres;
    nodes += body.mesh.node_count();
    spheres += static_cast<std::uint32_t>(body.layout.size());
    setup.bodies.push_back(std::move(body));
  }
  if (setup.bodies.size() == 1) {
    setup.mesh = setup.bodies.front().mesh;
    setup.layout = setup.bodies.front().layout;
  } else {
    std::vector<Eigen::Vector3d> positions;
    std::vector<geometry::Tet> tets;
    std::vector<const sphere_layout::SphereLayout*> layouts;
    std::vector<std::size_t> offsets;
    for (const TissueBody& body : setup.bodies) {
      const auto offset = static_cast<geometry::Index>(body.first_node);
      positions.insert(positions.end(), body.mesh.rest_positions().begin(),
                       body.mesh.rest_positions().end());
      for (geometry::Tet t : body.mesh.tets()) {
        for (auto& n : t) n += offset;
        tets.push_back(t);
      }
      layouts.push_back(&body.layout);
      offsets.push_back(body.first_node);
    }
    setup.mesh = geometry::TetMesh(std::move(positions), std::move(tets));
    setup.layout = sphere_layout::concatenate(layouts, offsets);
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
    const bool tissue = std::find(plan.fem_bodies.begin(), plan.fem_bodies.end(), pair.first) !=
                        plan.fem_bodies.end();
    if (pair.kind == scene::PairKind::kHard && tissue) {
      if (fem_keeps_anatomy) continue;
      // Tested against the joined tissue once, whichever bodies it is near.
      const std::size_t a = anatomy_index(pair.second);
      if (std::find(setup.tissue_obstacles.begin(), setup.tissue_obstacles.end(), a) ==
          setup.tissue_obstacles.end())
        setup.tissue_obstacles.push_back(a);
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
