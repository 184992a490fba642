// Builds a scene's deformable body for the FEM service: the tet mesh in the
// world frame, fixed nodes, FEM settings from the scene, and the AIST
// sphere links the ContactSets refer to (the same deterministic filling the
// haptic service computes, so sphere ids agree without a handshake).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "fahr/fem/body.h"
#include "fahr/fem/sphere_links.h"
#include "fahr/geometry/tet_mesh.h"
#include "fahr/scene/scene.h"

namespace fahr::fem_service {

struct FemBodySetup {
  const scene::Body* scene_body = nullptr;
  geometry::TetMesh mesh;  // world frame, m
  std::vector<std::uint32_t> fixed_nodes;
  fem::BodySettings settings;
  fem::SphereLinks links;
  std::unique_ptr<fem::Body> body;
};

// Throws std::runtime_error naming the body and what is wrong.
FemBodySetup set_up_body(const scene::Scene& scene, const scene::Body& body);

}  // namespace fahr::fem_service
