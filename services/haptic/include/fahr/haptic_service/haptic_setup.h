// Builds what the haptic service's loop needs from a scene, once, before
// the first tick: each deformable body's AIST (the same deterministic
// filling as fahr_fem_service, so sphere ids agree; every ContactSet carries
// the layout's fingerprint and the FEM refuses a set of another), the tool's
// signed distance field in its own frame, the obstacles' fields in theirs,
// and the contact response settings.
//
// Several deformable bodies are one tissue to the tick: their meshes and
// layouts joined (nodes and spheres of each body after those of the bodies
// before it, in the scene's order), queried through one sphere tree, their
// compliance blocks one block-diagonal W (no body moves another), the
// ContactSet split back into one per body (docs/design/two-deformable-bodies.md).
#pragma once

#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "fahr/collision/field_grid.h"
#include "fahr/collision/surface_samples.h"
#include "fahr/contact/contact_response.h"
#include "fahr/contact/penalty_response.h"
#include "fahr/geometry/signed_distance_field.h"
#include "fahr/geometry/surface_mesh.h"
#include "fahr/geometry/tet_mesh.h"
#include "fahr/runtime/rigid_field.h"
#include "fahr/scene/scene.h"
#include "fahr/sphere_layout/fill_settings.h"
#include "fahr/sphere_layout/sphere_layout.h"

namespace fahr::haptic_service {

// A rigid body's surface and its field, built as the FEM service builds the
// same anatomy's (libs/runtime).
using RigidField = runtime::RigidField;

// How the tool's contacts with the deformable body are found.
enum class CollisionMethod {
  kAist,      // the adaptive inner sphere tree (the paper's method)
  kTriangle,  // the triangle-level baseline (Bullet box trees, vertex-face)
};

// What the triangle baseline needs beyond the AIST: the body's boundary and,
// per boundary vertex, the sphere whose compliance and ContactSet entry its
// contacts use (the nearest sphere at rest), so both methods feed the same
// response and the same FEM.
struct TriangleCollisionSetup {
  geometry::SurfaceMesh boundary;                // world frame, rest, m
  std::vector<geometry::Index> surface_to_node;  // FEM node of each boundary vertex
  std::vector<std::uint32_t> vertex_sphere;      // sphere id of each boundary vertex
};

// Deformable bodies a scene may give the haptic service: each adds its W
// block to the joined one, which grows with the square of the count.
inline constexpr std::size_t kMaxTissueBodies = 4;

// One deformable body of the tissue.
struct TissueBody {
  const scene::Body* body = nullptr;
  geometry::TetMesh mesh;                // world frame, m (the FEM service's frame too)
  sphere_layout::SphereLayout layout;    // the FEM service's, sphere ids its own
  std::uint64_t layout_fingerprint = 0;  // layout.fingerprint(), in its ContactSets
  std::size_t first_node = 0;            // its first node in HapticSetup::mesh
  std::uint32_t first_sphere = 0;        // its first sphere in HapticSetup::layout
};

struct HapticSetup {
  const scene::Scene* scene = nullptr;
  // The deformable bodies, in the scene's order (at least one).
  std::vector<TissueBody> bodies;
  // The tissue the tick queries: the bodies' meshes and layouts joined (with
  // one body, its own).
  geometry::TetMesh mesh;
  sphere_layout::SphereLayout layout;
  std::unique_ptr<RigidField> tool;
  // The tool field's grid in the compact form the tick's AIST query reads
  // (one cell per sphere, single precision: haptic/field_grid.h).
  std::unique_ptr<collision::FieldGrid> tool_grid;
  // Points on the tool's surface (tool frame) tested against the anatomy.
  collision::SurfaceSamples tool_samples;
  // Every rigid body either side touches, loaded once.
  std::vector<std::unique_ptr<RigidField>> anatomy;
  // Indices into anatomy: what the deformable body is tested against (the
  // plan's hard pairs), and what the tool is (its tool-obstacle pairs).
  std::vector<std::size_t> tissue_obstacles;
  std::vector<std::size_t> tool_obstacles;
  contact::ResponseSettings response;
  // contact.response: penalty: the baseline of the paper's Figure 7a (the
  // tool follows the device rigidly; forces k_p d on the FEM, no projection).
  bool penalty = false;
  contact::PenaltySettings penalty_settings;
  CollisionMethod collision = CollisionMethod::kAist;
  std::unique_ptr<TriangleCollisionSetup> triangles;  // set for kTriangle only
  // Spheres within this gap of the tool are reported by the query
  // (candidates), m, >= 0, and the deepest of them are the FEM's W requests.
  // The walk also visits spheres 1 mm beyond it, to remember their centres
  // outside.
  double candidate_margin_m = 1e-3;
  // Candidates within this gap are rows too (lambda = 0 until the proxy
  // moves into them), m, in [0, candidate_margin_m]: the solve then stops
  // the proxy within the tick instead of one tick late, which takes a tick's
  // travel (0.5 mm is a 0.5 m/s hand's). The band between it and the
  // candidate margin is the look-ahead for W: a sphere's W arrives one or
  // two FEM periods after it is asked for (10 ms at 200 Hz), so a sphere
  // entering the candidate margin has W before it is a row while the hand
  // approaches at up to 50 mm/s (docs/design/compliance-block.md).
  double row_margin_m = 0.5e-3;
};

// The body (index into HapticSetup::bodies) a sphere of the joined layout
// belongs to.
std::size_t body_of_sphere(const HapticSetup& setup, std::uint32_t sphere);
// The bodies' ids (their DDS keys), in HapticSetup::bodies' order.
std::vector<std::uint32_t> body_ids(const HapticSetup& setup);

// Throws std::runtime_error naming the body and what is wrong.
// fem_keeps_anatomy: the FEM keeps the tongue out of the anatomy itself
// (fem/obstacle_projection.h; the FEM service always does), so the tongue
// is not tested against the anatomy here and the ContactSet carries no
// obstacle entries, which that FEM ignores. false: the haptic side finds
// them, for a FEM without its own anatomy (stack_sim's --fem-anatomy off).
HapticSetup set_up(const scene::Scene& scene, CollisionMethod collision = CollisionMethod::kAist,
                   bool fem_keeps_anatomy = true);

}  // namespace fahr::haptic_service
