// SceneDescription samples (one per body, transient local) so a late
// logger or visualiser learns the scene, the meshes and the sphere layout.
#pragma once

#include <vector>

#include "fahr/haptic_service/haptic_setup.h"
#include "scene_description.h"

namespace fahr::haptic_service {

// One sample per scene body: the deformable body with its rest mesh and
// AIST layout, rigid bodies with name, role and mesh path only.
std::vector<msg::SceneDescription> describe_scene(const HapticSetup& setup);

}  // namespace fahr::haptic_service
