// Rigid scene bodies' fields, and which of them a deformable body meets.
#include "fahr/runtime/rigid_field.h"

#include <cstdlib>
#include <stdexcept>
#include <string>

#include "fahr/geometry/surface_loader.h"
#include "fahr/scene/plan.h"

namespace fahr::runtime {

Eigen::Isometry3d RigidField::world_from_body() const {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translate(scene_body->pose.position_m);
  pose.rotate(scene_body->pose.orientation);
  return pose;
}

std::filesystem::path field_cache_dir() {
  if (const char* dir = std::getenv("FAHR_CACHE_DIR"); dir != nullptr && *dir != '\0') {
    if (std::string(dir) == "off") return {};
    return std::filesystem::path(dir) / "fields";
  }
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg == '/') {
    return std::filesystem::path(xdg) / "fahr" / "fields";
  }
  if (const char* home = std::getenv("HOME"); home != nullptr && *home == '/') {
    return std::filesystem::path(home) / ".cache" / "fahr" / "fields";
  }
  return {};
}

std::string describe_field_sources(const std::vector<const RigidField*>& fields) {
  int read = 0;
  int built = 0;
  std::string notes;
  for (const RigidField* field : fields) {
    if (field == nullptr || !field->sdf) continue;
    if (field->sdf->grid_source() == geometry::SdfGridSource::kCacheHit) {
      ++read;
    } else {
      ++built;
    }
    if (!field->sdf->cache_note().empty()) notes += "; " + field->sdf->cache_note();
  }
  return "fields: " + std::to_string(read) + " read from the cache, " + std::to_string(built) +
         " built" + notes;
}

std::unique_ptr<RigidField> load_rigid_field(const scene::Body& body) {
  auto field = std::make_unique<RigidField>();
  field->scene_body = &body;
  field->surface = geometry::load_surface(body.mesh_path, body.mesh_scale);
  geometry::SdfOptions options;
  options.cell_size_m = body.rigid ? body.rigid->sdf_cell_m : options.cell_size_m;
  options.cache_dir = field_cache_dir();
  try {
    field->sdf = std::make_unique<geometry::SignedDistanceField>(field->surface, options);
  } catch (const std::exception& e) {
    throw std::runtime_error("body '" + body.name + "' (" + body.mesh_path.string() +
                             "): signed distance field: " + e.what());
  }
  return field;
}

std::vector<std::size_t> hard_obstacles_of(const scene::Scene& scene, std::size_t deformable) {
  std::vector<std::size_t> obstacles;
  for (const scene::BodyPair& pair : scene::derive_plan(scene).pairs) {
    if (pair.kind == scene::PairKind::kHard && pair.first == deformable)
      obstacles.push_back(pair.second);
  }
  return obstacles;
}

}  // namespace fahr::runtime
