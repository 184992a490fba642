// A rigid scene body's surface and signed distance field, built the same way
// by every service that keeps something out of it (the haptic service: the
// blade and the tongue's spheres; the FEM service: the tongue's nodes), so
// both see the same bone.
#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "fahr/geometry/signed_distance_field.h"
#include "fahr/geometry/surface_mesh.h"
#include "fahr/scene/scene.h"

namespace fahr::runtime {

// Held through a pointer so the field (which refers to the surface's
// triangles) never sees its surface move.
struct RigidField {
  const scene::Body* scene_body = nullptr;
  geometry::SurfaceMesh surface;  // body frame, m
  std::unique_ptr<geometry::SignedDistanceField> sdf;

  // The body's pose: world_from_body.
  Eigen::Isometry3d world_from_body() const;
};

// Where fields are kept between runs (geometry::SdfOptions::cache_dir):
// $FAHR_CACHE_DIR/fields; else $XDG_CACHE_HOME/fahr/fields; else
// $HOME/.cache/fahr/fields. FAHR_CACHE_DIR=off (or no HOME) keeps none.
std::filesystem::path field_cache_dir();

// Loads the body's surface (its unit) and builds its field on the body's
// sdf_cell_m grid, or reads it from field_cache_dir(). Throws
// std::runtime_error naming the body and the file.
std::unique_ptr<RigidField> load_rigid_field(const scene::Body& body);

// For a service's set-up line: "fields: 3 read from the cache, 6 built" and
// any cache problem met (a refused file, an unwritable directory).
std::string describe_field_sources(const std::vector<const RigidField*>& fields);

// The obstacle bodies (indices into scene.bodies) the deformable body
// `deformable` (an index too) is held out of: the scene plan's hard pairs.
std::vector<std::size_t> hard_obstacles_of(const scene::Scene& scene, std::size_t deformable);

}  // namespace fahr::runtime
