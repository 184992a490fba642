// SphereState: centres and radii of one FEM state.
#include "fahr/haptic/sphere_state.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace fahr::haptic {
namespace {

// Six times the signed volume of a tet from flat positions, m^3.
double six_volume(const geometry::Tet& t, const double* x) {
  const Eigen::Vector3d a(x + 3 * t[0]);
  const Eigen::Vector3d b = Eigen::Vector3d(x + 3 * t[1]) - a;
  const Eigen::Vector3d c = Eigen::Vector3d(x + 3 * t[2]) - a;
  const Eigen::Vector3d d = Eigen::Vector3d(x + 3 * t[3]) - a;
  return b.dot(c.cross(d));
}

}  // namespace

SphereState::SphereState(const SphereLayout& layout)
    : centres_m_(layout.size(), Eigen::Vector3d::Zero()),
      radii_m_(layout.size(), 0.0),
      six_volume_m3_(layout.tets().size(), 0.0) {
  reset_to_rest(layout);
}

void SphereState::reset_to_rest(const SphereLayout& layout) {
  for (std::size_t i = 0; i < layout.size(); ++i) {
    centres_m_[i] = layout.sphere(i).rest_centre_m;
    radii_m_[i] = layout.sphere(i).rest_radius_m;
  }
  ++version_;
}

bool SphereState::update(const SphereLayout& layout, std::span<const double> positions_m) {
  if (positions_m.size() < 3 * layout.node_count()) return false;
  const double* x = positions_m.data();
  const std::vector<geometry::Tet>& tets = layout.tets();
  // Each tet's volume once: a tet is linked to several spheres.
  for (std::size_t t = 0; t < tets.size(); ++t) six_volume_m3_[t] = six_volume(tets[t], x);
  for (std::size_t i = 0; i < layout.size(); ++i) {
    const SphereRecord& s = layout.sphere(i);
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    const auto nodes = layout.nodes(i);
    const auto weights = layout.weights(i);
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      c += weights[k] * Eigen::Vector3d(x + 3 * std::size_t{nodes[k]});
    }
    if (!c.allFinite()) return false;
    double six_v = 0.0;
    for (const std::uint32_t t : layout.tets_of(i)) six_v += six_volume_m3_[t];
    const double ratio = six_v / (6.0 * s.rest_linked_volume_m3);
    // cbrt keeps the sphere's volume proportional to its tets' volume.
    const double scale = ratio > kMinVolumeScale * kMinVolumeScale * kMinVolumeScale
                             ? std::min(std::cbrt(ratio), kMaxVolumeScale)
                             : kMinVolumeScale;
    centres_m_[i] = c;
    radii_m_[i] = s.rest_radius_m * scale;
  }
  ++version_;
  return true;
}

}  // namespace fahr::haptic
