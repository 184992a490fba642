// Builds what the haptic service's loop needs from a scene, once, before
// the first tick: the deformable body's AIST (the same deterministic filling
// as fahr_fem_service, so sphere ids agree without a handshake), the tool's
// signed distance field in its own frame, the obstacles' fields in theirs,
// and the contact response settings.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "fahr/contact/contact_response.h"
#include "fahr/geometry/signed_distance_field.h"
#include "fahr/geometry/surface_mesh.h"
#include "fahr/geometry/tet_mesh.h"
#include "fahr/haptic/fill_settings.h"
#include "fahr/haptic/sphere_layout.h"
#include "fahr/scene/scene.h"

namespace fahr::haptic_service {

// A rigid body's surface and its field. Held through a pointer so the field
// (which refers to the surface's triangles) never sees its surface move.
struct RigidField {
  const scene::Body* scene_body = nullptr;
  geometry::SurfaceMesh surface;  // body frame, m
  std::unique_ptr<geometry::SignedDistanceField> sdf;
};

struct HapticSetup {
  const scene::Scene* scene = nullptr;
  const scene::Body* deformable = nullptr;
  geometry::TetMesh mesh;  // world frame, m (the FEM service's frame too)
  haptic::SphereLayout layout;
  std::unique_ptr<RigidField> tool;
  // Obstacles the deformable body is tested against (the plan's hard pairs).
  std::vector<std::unique_ptr<RigidField>> obstacles;
  contact::ResponseSettings response;
};

// The FEM service's mapping of the scene's aist block (kept identical: a
// different mapping would give different sphere ids on the two sides).

// Throws std::runtime_error naming the body and what is wrong.
HapticSetup set_up(const scene::Scene& scene);

}  // namespace fahr::haptic_service
