// Builds a scene's deformable body for the FEM service: the tet mesh in the
// world frame, fixed nodes, FEM settings from the scene, the AIST sphere
// links the ContactSets refer to (the same deterministic filling the haptic
// service computes, so sphere ids agree; the layout's fingerprint, which
// every ContactSet must carry, proves it), and the rigid anatomy the body
// keeps its nodes out of.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fahr/fem/body.h"
#include "fahr/fem/obstacle_projection.h"
#include "fahr/fem/sphere_links.h"
#include "fahr/fem/volume_floor.h"
#include "fahr/fem_service/anatomy_fields.h"
#include "fahr/geometry/tet_mesh.h"
#include "fahr/scene/scene.h"

namespace fahr::fem_service {

struct FemBodySetup {
  const scene::Body* scene_body = nullptr;
  geometry::TetMesh mesh;  // world frame, m
  std::vector<std::uint32_t> fixed_nodes;
  fem::BodySettings settings;
  fem::SphereLinks links;
  // SphereLayout::fingerprint() of the layout the links come from: a
  // ContactSet must carry the same (layout_check.h).
  std::uint64_t layout_fingerprint = 0;
  std::unique_ptr<fem::Body> body;
  // The obstacles of the scene's hard pairs with this body (world frame),
  // enforced by the FEM step itself (docs/design/anatomy-contact.md).
  std::vector<std::unique_ptr<AnatomyField>> anatomy;
  fem::ObstacleProjectionSettings anatomy_settings;
  // false: the step leaves the anatomy to the ContactSet's obstacle entries
  // (the fields stay loaded, for diagnostics); only a benchmark's comparison
  // sets it (stack_sim::Experiments::haptic_side_anatomy).
  bool enforce_anatomy = true;
  // The scene's solver.compliance_columns: normals (ContactStepSettings).
  bool compliance_along_normals = false;
  // The scene's solver.volume_floor_ratio (libs/fem volume_floor.h).
  fem::VolumeFloorSettings volume_floor{};
};

// Throws std::runtime_error naming the body and what is wrong. `install`:
// whether a step waits for a late background factorisation (lockstep, the
// default) or goes on without it (real time; fem SolverSettings::factor_install).
FemBodySetup set_up_body(const scene::Scene& scene, const scene::Body& body,
                         fem::FactorInstall install = fem::FactorInstall::kWait);

}  // namespace fahr::fem_service
