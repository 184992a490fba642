// Suggested poses of a blade's tool frame in the head frame, shared by the
// meshes/neonatal/README.md, the renderer and the generator's own collision check. A pose is a
// rotation about the head frame's z axis (the blade stays in the
// mid-sagittal plane) followed by a translation of the tool origin (the tip).
#pragma once

#include <string>
#include <vector>

#include "fahr/scenegen/geometry_types.h"

namespace fahr::scenegen {

struct BladePose {
  std::string name;
  double pitch_deg = 0.0;  // rotation about +z; positive lifts the heel (tip goes down)
  Vec3 tip_mm = Vec3::Zero();

  Vec3 apply(const Vec3& tool_point) const;
};

// "initial": the tip just in front of the lips, blade level along the oral
// axis. "pressing": the tip past the tongue's crest, the spatula pressing
// the dorsum down by a few millimetres (it intersects the rest tongue; the
// FEM resolves that).
std::vector<BladePose> suggested_blade_poses();

TriangleMesh transformed(const TriangleMesh& mesh, const BladePose& pose);

}  // namespace fahr::scenegen
