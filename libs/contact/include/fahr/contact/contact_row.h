// One row of the tool's contact problem: the rigid tool against one tissue
// sphere (yields with the FEM's compliance) or against one rigid obstacle
// feature (does not yield), measured with the tool at a reference pose p0.
#pragma once

#include <Eigen/Core>
#include <cstdint>

namespace fahr::contact {

enum class RowKind : std::uint8_t {
  kTissue,    // tool vs AIST sphere of a deformable body: force-aware
  kObstacle,  // tool vs rigid anatomy (face, lips, palate, jaw, trachea): always hard, W = 0
};

// Index into TissueCompliance::sphere_ids meaning "no compliance block".
inline constexpr std::int32_t kNoCompliance = -1;

struct ContactRow {
  RowKind kind = RowKind::kTissue;
  // Tissue: the sphere id (index into the body's SphereLinks). Obstacle: the
  // caller's feature id. (kind, id) keys the warm start across ticks.
  std::uint32_t id = 0;
  // Unit normal from the tool surface toward the other body: for a tissue
  // sphere (c - q)/|c - q| as in ContactSet; for an obstacle minus its
  // outward normal. Moving the tool by dp deepens the row by n . dp.
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();
  // q: nearest tool point with the tool at the reference pose p0, m.
  Eigen::Vector3d tool_point_m = Eigen::Vector3d::Zero();
  // Tissue: the sphere centre of the FEM's free motion, m (which centre:
  // docs/design/contact-contract.md). Obstacle: the nearest obstacle
  // surface point, m.
  Eigen::Vector3d other_point_m = Eigen::Vector3d::Zero();
  // Sphere radius r, m, >= 0; 0 for obstacles.
  double radius_m = 0.0;
  // Tissue: index of the sphere in TissueCompliance::sphere_ids, or
  // kNoCompliance (the solver then leaves the row out). Ignored for
  // obstacles.
  std::int32_t compliance_index = kNoCompliance;

  // d = r - (c - q) . n, m: > 0 penetrating, < 0 separated.
  double penetration_m() const { return radius_m - (other_point_m - tool_point_m).dot(normal); }
};

}  // namespace fahr::contact
