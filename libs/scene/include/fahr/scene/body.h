// One body of a scene: a deformable FEM body, the rigid tool the device
// drives, or rigid anatomy the others bump into.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fahr/scene/aabb.h"
#include "fahr/scene/defaults.h"
#include "fahr/scene/pose.h"

namespace fahr::scene {

enum class BodyRole {
  kDeformable,  // tetrahedral FEM body with an AIST
  kTool,        // rigid, follows the device through the proxy
  kObstacle,    // rigid, never moves
};

// Length unit of the coordinates in a mesh file.
enum class LengthUnit { kMetre, kCentimetre, kMillimetre };

std::string_view to_string(BodyRole role);
std::string_view to_string(LengthUnit unit);
// Metres per file unit: the scale a mesh loader multiplies coordinates by.
double metres_per_unit(LengthUnit unit);

// The FEM material model (libs/fem material.h): corotational linear
// elasticity, or the Stable Neo-Hookean hyperelastic solid.
enum class MaterialModel { kCorotational, kStableNeoHookean };

std::string_view to_string(MaterialModel model);

// Isotropic elastic material in SI units, its model, optionally stiffening
// under large compression.
struct Material {
  double youngs_modulus_pa = kDefaultYoungsModulusPa;        // Pa, (0, 1e12]
  double poisson_ratio = kDefaultPoissonRatio;               // (-1, 0.5)
  double density_kg_per_m3 = kDefaultDensityKgPerM3;         // kg/m^3, (0, 1e5]
  double rayleigh_mass_per_s = kDefaultRayleighMassPerS;     // 1/s, [0, 1e4]
  double rayleigh_stiffness_s = kDefaultRayleighStiffnessS;  // s, [0, 10]
  // Yeoh C20/C10, dimensionless, [0, 100]; 0: no compression stiffening.
  double yeoh_c20_over_c10 = kDefaultYeohC20OverC10;
  // corotational by default: a scene without the key behaves as before it.
  MaterialModel model = MaterialModel::kCorotational;
};

// Nodes held at their rest position: the union of an index file and a box.
struct FixedNodes {
  // Empty when the scene names no file. One index per line, '#' comments.
  std::filesystem::path nodes_file;
  // Zero-based node indices read from nodes_file (sorted, unique); empty when
  // the loader did not read files (LoadOptions::check_files false).
  std::vector<std::uint32_t> node_indices;
  bool node_indices_loaded = false;
  // Nodes whose rest position (world frame) lies in this box are fixed too.
  std::optional<Aabb> box;
};

// Adaptive inner sphere tree settings (docs/design/aist-layout.md).
struct AistSettings {
  // Coarse sphere volume over mean tet volume, (0, 1000].
  double sphere_tet_volume_ratio = kDefaultSphereTetVolumeRatio;
  int refinement_levels = kDefaultRefinementLevels;  // octree levels, [0, 8]
  bool surface_spheres = kDefaultSurfaceSpheres;     // surface-hugging spheres
  int sphere_budget = kDefaultSphereBudget;          // max spheres, [1, 65536]
};

struct DeformableSettings {
  Material material;
  FixedNodes fixed;
  AistSettings aist;
};

struct RigidSettings {
  // Signed distance field grid cell, m, [1e-5, 1e-2].
  double sdf_cell_m = kDefaultSdfCellM;
};

struct Body {
  std::string name;      // unique; [A-Za-z0-9_-], 1-64 chars (idl string<64>)
  std::uint32_t id = 0;  // unique; the DDS key of per-body topics
  BodyRole role = BodyRole::kObstacle;
  // Absolute (resolved against the scene file's folder). A deformable body's
  // mesh is a tet mesh: TetGen .node (with .ele, optional .face beside it),
  // Gmsh .msh or legacy VTK .vtk; a rigid body's a surface: .obj, .stl, .ply.
  std::filesystem::path mesh_path;
  // The path as written in the scene file, for messages and SceneDescription.
  std::string mesh_uri;
  LengthUnit mesh_unit = LengthUnit::kMetre;
  double mesh_scale = 1.0;  // metres per mesh unit: 1, 0.01 or 0.001
  // world_from_body; for the tool, its initial pose.
  Pose pose;
  std::optional<DeformableSettings> deformable;  // set iff role is deformable
  std::optional<RigidSettings> rigid;            // set iff role is rigid
};

}  // namespace fahr::scene
