// The bodies section: names, ids, roles, meshes and their units, poses, and
// the deformable or rigid settings of each body.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

#include "fahr/scene/node_index_file.h"
#include "parsers.h"

namespace fahr::scene::detail {

namespace {

constexpr std::string_view kTetExtensions[] = {".node", ".msh", ".vtk"};
constexpr std::string_view kSurfaceExtensions[] = {".obj", ".stl", ".ply"};

// Hand-typed quaternions have 3-4 digits; anything further from unit length
// is a mistake, not rounding.
constexpr double kQuaternionNormTolerance = 1.0e-3;

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

template <std::size_t N>
bool listed(const std::string_view (&list)[N], std::string_view ext) {
  return std::find(std::begin(list), std::end(list), ext) != std::end(list);
}

template <std::size_t N>
std::string joined(const std::string_view (&list)[N]) {
  std::string out;
  for (const std::string_view item : list) out += (out.empty() ? "" : ", ") + std::string(item);
  return out;
}

void check_file_exists(const ParseContext& ctx, const MapReader& map, std::string_view key,
                       const std::filesystem::path& path, std::string_view what) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    ctx.log.add(map.value(key).Mark(), map.child_path(key),
                std::string(what) + " not found: " + path.string());
  }
}

void parse_mesh(const ParseContext& ctx, const MapReader& map, Body& body) {
  if (!map.require("mesh") || !map.read("mesh", body.mesh_uri)) return;
  body.mesh_path = ctx.resolve(body.mesh_uri);
  const std::string ext = lower_extension(body.mesh_path);
  const bool deformable = body.role == BodyRole::kDeformable;
  if (deformable && !listed(kTetExtensions, ext)) {
    ctx.log.add(map.value("mesh").Mark(), map.child_path("mesh"),
                "a deformable body needs a tetrahedral mesh (" + joined(kTetExtensions) +
                    "), got '" + body.mesh_uri + "'");
    return;
  }
  if (!deformable && !listed(kSurfaceExtensions, ext)) {
    ctx.log.add(map.value("mesh").Mark(), map.child_path("mesh"),
                "a rigid body needs a surface mesh (" + joined(kSurfaceExtensions) + "), got '" +
                    body.mesh_uri + "'");
    return;
  }
  if (!ctx.options.check_files) return;
  check_file_exists(ctx, map, "mesh", body.mesh_path, "mesh file");
  if (ext == ".node") {
    // TetGen keeps the tets in a sibling .ele file.
    std::filesystem::path ele = body.mesh_path;
    ele.replace_extension(".ele");
    check_file_exists(ctx, map, "mesh", ele, "TetGen element file");
  }
}

void parse_unit(const MapReader& map, Body& body) {
  if (!map.require("unit")) return;
  if (map.read_enum("unit", kLengthUnitNames, body.mesh_unit)) {
    body.mesh_scale = metres_per_unit(body.mesh_unit);
  }
}

Material parse_material(const MapReader& body_map) {
  Material m;
  const MapReader map(
      body_map.log(), body_map.value("material"), body_map.child_path("material"),
      {"youngs_modulus_pa", "poisson_ratio", "density_kg_per_m3", "rayleigh_mass_per_s",
       "rayleigh_stiffness_s", "yeoh_c20_over_c10", "model"});
  map.read("youngs_modulus_pa", open_closed(0.0, 1.0e12), m.youngs_modulus_pa);
  // nu = 0.5 is incompressible (the stiffness matrix is singular), nu = -1
  // has no shear stiffness: both ends excluded.
  map.read("poisson_ratio", open(-1.0, 0.5), m.poisson_ratio);
  map.read("density_kg_per_m3", open_closed(0.0, 1.0e5), m.density_kg_per_m3);
  map.read("rayleigh_mass_per_s", closed(0.0, 1.0e4), m.rayleigh_mass_per_s);
  map.read("rayleigh_stiffness_s", closed(0.0, 10.0), m.rayleigh_stiffness_s);
  // The FEM's own bound (libs/fem material.h, kMaxYeohC20OverC10).
  map.read("yeoh_c20_over_c10", closed(0.0, 100.0), m.yeoh_c20_over_c10);
  map.read_enum("model", kMaterialModelNames, m.model);
  return m;
}

std::optional<Aabb> parse_box(const MapReader& parent, std::string_view key) {
  const MapReader map(parent.log(), parent.value(key), parent.child_path(key), {"min", "max"});
  if (!map.is_map()) return std::nullopt;
  Aabb box;
  const Range any = closed(-1.0e3, 1.0e3);
  const bool has_min = map.require("min");
  const bool has_max = map.require("max");  // reported even when min is missing
  if (!has_min || !has_max) return std::nullopt;
  const bool min_ok = map.read("min", any, box.min_m);
  const bool max_ok = map.read("max", any, box.max_m);
  if (!min_ok || !max_ok) return std::nullopt;
  if (!(box.min_m.array() < box.max_m.array()).all()) {
    map.log().add(map.mark(), map.path(), "min must be below max on every axis");
    return std::nullopt;
  }
  return box;
}

FixedNodes parse_fixed(const ParseContext& ctx, const MapReader& body_map) {
  FixedNodes fixed;
  const MapReader map(ctx.log, body_map.value("fixed"), body_map.child_path("fixed"),
                      {"nodes_file", "nodes_index_base", "box_m"});
  if (!map.is_map()) return fixed;
  if (!map.has("nodes_file") && !map.has("box_m")) {
    ctx.log.add(map.mark(), map.path(), "give nodes_file, box_m or both");
  }
  int index_base = 0;
  if (map.has("nodes_index_base") && !map.has("nodes_file")) {
    map.reject("nodes_index_base", "it applies to nodes_file, which is not given");
  }
  map.read("nodes_index_base", 0, 1, index_base);
  if (map.has("box_m")) fixed.box = parse_box(map, "box_m");
  std::string file;
  if (!map.read("nodes_file", file)) return fixed;
  fixed.nodes_file = ctx.resolve(file);
  if (!ctx.options.check_files) return fixed;
  try {
    fixed.node_indices = read_node_index_file(fixed.nodes_file, index_base);
    fixed.node_indices_loaded = true;
  } catch (const SceneError& error) {
    // The file's own line is in the message; the scene line says who asked.
    ctx.log.add(map.value("nodes_file").Mark(), map.child_path("nodes_file"),
                error.issues().front().to_string());
  }
  return fixed;
}

AistSettings parse_aist(const MapReader& body_map) {
  AistSettings aist;
  const MapReader map(
      body_map.log(), body_map.value("aist"), body_map.child_path("aist"),
      {"sphere_tet_volume_ratio", "refinement_levels", "surface_spheres", "sphere_budget"});
  map.read("sphere_tet_volume_ratio", open_closed(0.0, 1000.0), aist.sphere_tet_volume_ratio);
  // Each level splits a boundary cell in 8: beyond 8 levels is 8^8 cells.
  map.read("refinement_levels", 0, 8, aist.refinement_levels);
  map.read("surface_spheres", aist.surface_spheres);
  map.read("sphere_budget", 1, kMaxSpheres, aist.sphere_budget);
  return aist;
}

void parse_role_settings(const ParseContext& ctx, const MapReader& map, Body& body) {
  const char* const deformable_keys[] = {"material", "fixed", "aist"};
  if (body.role == BodyRole::kDeformable) {
    DeformableSettings settings;
    if (map.has("material")) settings.material = parse_material(map);
    if (map.has("fixed")) settings.fixed = parse_fixed(ctx, map);
    if (map.has("aist")) settings.aist = parse_aist(map);
    if (map.has("sdf_cell_m")) {
      map.reject("sdf_cell_m", "only rigid bodies (tool, obstacle) have a distance field");
    }
    body.deformable = settings;
    return;
  }
  for (const char* key : deformable_keys) {
    if (map.has(key)) {
      map.reject(key, "only deformable bodies have it (this body is a " +
                          std::string(to_string(body.role)) + ")");
    }
  }
  RigidSettings rigid;
  map.read("sdf_cell_m", closed(1.0e-5, 1.0e-2), rigid.sdf_cell_m);
  body.rigid = rigid;
}

Body parse_body(const ParseContext& ctx, const YAML::Node& node, std::size_t index) {
  Body body;
  body.id = static_cast<std::uint32_t>(index + 1);
  const std::string path = "bodies[" + std::to_string(index) + "]";
  const MapReader map(
      ctx.log, node, path,
      {"name", "id", "role", "mesh", "unit", "pose", "material", "fixed", "aist", "sdf_cell_m"});
  if (!map.is_map()) return body;
  if (map.require("name") && map.read("name", body.name) && !is_valid_name(body.name)) {
    ctx.log.add(map.value("name").Mark(), map.child_path("name"),
                "'" + body.name + "' is not a valid name: use 1-64 of A-Z a-z 0-9 _ -");
  }
  long long id = body.id;
  if (map.has("id") && read_int(ctx.log, map.value("id"), map.child_path("id"), 0,
                                std::numeric_limits<std::uint32_t>::max(), id)) {
    body.id = static_cast<std::uint32_t>(id);
  }
  const bool has_role = map.require("role") && map.read_enum("role", kBodyRoleNames, body.role);
  if (has_role) parse_mesh(ctx, map, body);
  parse_unit(map, body);
  if (map.has("pose")) body.pose = parse_pose(ctx, map.value("pose"), map.child_path("pose"));
  if (has_role) parse_role_settings(ctx, map, body);
  return body;
}

// Names, ids and the single tool are checked across bodies, at the later one.
void check_unique(const ParseContext& ctx, const YAML::Node& list,
                  const std::vector<Body>& bodies) {
  std::optional<std::size_t> tool;
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    const YAML::Node node = list[i];
    if (!node.IsMap()) continue;  // already reported; subscripting a scalar throws
    const std::string path = "bodies[" + std::to_string(i) + "]";
    for (std::size_t j = 0; j < i; ++j) {
      if (!bodies[i].name.empty() && bodies[i].name == bodies[j].name) {
        ctx.log.add(node["name"].Mark(), path + ".name",
                    "duplicate body name '" + bodies[i].name + "' (also bodies[" +
                        std::to_string(j) + "])");
      }
      if (bodies[i].id == bodies[j].id) {
        const YAML::Node id = node["id"];
        ctx.log.add(id.IsDefined() ? id.Mark() : node.Mark(), path + ".id",
                    "duplicate body id " + std::to_string(bodies[i].id) + " (also bodies[" +
                        std::to_string(j) + "]; ids default to position + 1)");
      }
    }
    if (bodies[i].role != BodyRole::kTool || !node["role"].IsDefined()) continue;
    if (tool) {
      ctx.log.add(node["role"].Mark(), path + ".role",
                  "a second tool ('" + bodies[i].name + "' after '" + bodies[*tool].name +
                      "'): the device drives exactly one tool; make the others obstacles "
                      "or comment them out");
    } else {
      tool = i;
    }
  }
}

}  // namespace

std::filesystem::path ParseContext::resolve(const std::string& path) const {
  const std::filesystem::path p(path);
  return (p.is_absolute() ? p : base_dir / p).lexically_normal();
}

bool is_valid_name(std::string_view name) {
  if (name.empty() || name.size() > 64) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  });
}

Pose parse_pose(const ParseContext& ctx, const YAML::Node& node, const std::string& path) {
  Pose pose;
  const MapReader map(ctx.log, node, path,
                      {"position_m", "orientation_rpy_deg", "orientation_quat_wxyz"});
  map.read("position_m", closed(-1.0e3, 1.0e3), pose.position_m);
  if (map.has("orientation_rpy_deg") && map.has("orientation_quat_wxyz")) {
    map.reject("orientation_quat_wxyz", "give one orientation, not both");
    return pose;
  }
  Eigen::Vector3d rpy;
  if (map.read("orientation_rpy_deg", closed(-360.0, 360.0), rpy)) {
    pose.orientation = quaternion_from_rpy_deg(rpy.x(), rpy.y(), rpy.z());
  }
  if (!map.has("orientation_quat_wxyz")) return pose;
  const YAML::Node q = map.value("orientation_quat_wxyz");
  const std::string q_path = map.child_path("orientation_quat_wxyz");
  if (!q.IsSequence() || q.size() != 4) {
    ctx.log.add(q.Mark(), q_path, "expected [w, x, y, z], got " + describe(q));
    return pose;
  }
  double wxyz[4] = {1.0, 0.0, 0.0, 0.0};
  bool ok = true;
  for (std::size_t i = 0; i < 4; ++i) {
    ok = read_double(ctx.log, q[i], q_path + "[" + std::to_string(i) + "]", closed(-1.0, 1.0),
                     wxyz[i]) &&
         ok;
  }
  if (!ok) return pose;
  const Eigen::Quaterniond quat(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  if (std::abs(quat.norm() - 1.0) > kQuaternionNormTolerance) {
    ctx.log.add(q.Mark(), q_path,
                "not a unit quaternion (norm " + std::to_string(quat.norm()) + ")");
    return pose;
  }
  pose.orientation = quat.normalized();
  return pose;
}

std::vector<Body> parse_bodies(const ParseContext& ctx, const MapReader& top) {
  std::vector<Body> bodies;
  if (!top.require("bodies")) return bodies;
  const YAML::Node list = top.value("bodies");
  if (!list.IsSequence() || list.size() == 0) {
    ctx.log.add(list.Mark(), "bodies",
                "expected a sequence of at least one body (- name: ...), got " + describe(list));
    return bodies;
  }
  for (std::size_t i = 0; i < list.size(); ++i) bodies.push_back(parse_body(ctx, list[i], i));
  check_unique(ctx, list, bodies);
  return bodies;
}

}  // namespace fahr::scene::detail
