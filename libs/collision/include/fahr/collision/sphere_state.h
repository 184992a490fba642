// The per-FEM-state part of the sphere tree: current centres and radii,
// recomputed from deformed node positions. Capacity fixed at construction;
// update() allocates nothing.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "fahr/sphere_layout/sphere_layout.h"

namespace fahr::collision {

class SphereState {
 public:
  SphereState() = default;
  explicit SphereState(const sphere_layout::SphereLayout& layout);
  // The smallest-stretch radius rule (see update()): rest_positions_m, 3 per
  // node (m), the layout's rest mesh. Throws std::invalid_argument when too
  // short or a linked tet is flat at rest.
  SphereState(const sphere_layout::SphereLayout& layout, std::span<const double> rest_positions_m);

  // positions_m: 3 per node (x, y, z), m, the FEM's flat layout. Centres are
  // c = sum w_i x_i; radii r = r0 cbrt(V / V0) over the linked tets, so a
  // compressed region's spheres shrink with it. With the smallest-stretch
  // rule (constructed with rest positions) r = r0 min over the linked tets of
  // the smallest singular value of their deformation gradient: an affine map
  // takes a ball of radius r0 to an ellipsoid whose smallest semi-axis is that,
  // so the sphere stays inside its rest sphere's image. Soft tissue keeps its
  // volume, so under a blade the volume rule keeps r0 while the tissue is
  // squashed toward the surface and the sphere stands out of it
  // (docs/design/aist-layout.md, radius rules). A linked volume that collapsed
  // or inverted (V <= 0) keeps kMinVolumeScale of the rest radius rather than
  // vanishing, and a stretch beyond kMaxVolumeScale is capped. Returns false (state unchanged past
  // the first bad node) if a position is not finite or the span is too short.
  bool update(const sphere_layout::SphereLayout& layout, std::span<const double> positions_m);

  // Also the deformed position of each sphere's surface anchor (sum w_i x_i
  // over its face's nodes) and of that face's nodes, NaN for a sphere
  // without one.

  // The rest state (same as update() with the rest positions).
  void reset_to_rest(const sphere_layout::SphereLayout& layout);

  const std::vector<Eigen::Vector3d>& centres_m() const { return centres_m_; }
  const std::vector<double>& radii_m() const { return radii_m_; }
  // Per sphere, m: its anchor on the deformed surface (sphere_layout::SurfaceAnchor), or
  // NaN (all three) for a sphere without one.
  const std::vector<Eigen::Vector3d>& anchors_m() const { return anchors_m_; }
  // Per sphere, m: the three deformed nodes of its anchor's face (NaN for a
  // sphere without an anchor), for QuerySettings::SurfaceProbe::kFacePoint.
  const std::vector<std::array<Eigen::Vector3d, 3>>& anchor_faces_m() const {
    return anchor_faces_m_;
  }
  std::uint64_t version() const { return version_; }  // bumped by every update

  // The radius scale of a sphere whose linked tets are inverted or flat: a
  // sphere still has to collide, and a tiny radius is a safe under-estimate.
  static constexpr double kMinVolumeScale = 0.25;
  // The largest radius scale: a sphere grown past its tets' surroundings
  // (large stretch, or a solver blow-up) would report contacts far from the
  // tissue; 1.5 is a volume stretch of 3.4, beyond soft tissue's range.
  static constexpr double kMaxVolumeScale = 1.5;

 private:
  std::vector<Eigen::Vector3d> centres_m_;
  std::vector<double> radii_m_;
  std::vector<Eigen::Vector3d> anchors_m_;
  std::vector<std::array<Eigen::Vector3d, 3>> anchor_faces_m_;
  std::vector<double> six_volume_m3_;  // per tet, scratch of update()
  // The smallest-stretch rule: per tet the inverse rest edge matrix, and the
  // smallest singular value (scratch of update()). Empty: the volume rule.
  std::vector<Eigen::Matrix3d> rest_inverse_;
  std::vector<double> smallest_stretch_;
  std::uint64_t version_ = 0;
};

}  // namespace fahr::collision
