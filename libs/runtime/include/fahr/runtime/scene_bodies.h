// What every service builds alike from a scene body, so the FEM and haptic
// services agree exactly: the tet mesh in the world frame and the AIST
// filling settings (the same deterministic filling gives the same sphere
// ids in both processes; the ContactSet's layout fingerprint checks it).
#pragma once

#include "fahr/geometry/tet_mesh.h"
#include "fahr/scene/body.h"
#include "fahr/sphere_layout/fill_settings.h"

namespace fahr::runtime {

// Loads the body's tet mesh (its unit) and moves it by its pose into the
// world frame, m. Throws geometry::LoadError naming file and line.
geometry::TetMesh world_tet_mesh(const scene::Body& body);

// The scene's `aist` section of a deformable body as filling settings.
sphere_layout::FillSettings fill_settings_for(const scene::Body& body);

}  // namespace fahr::runtime
