// SphereState: centres and radii of one FEM state.
#include "fahr/collision/sphere_state.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "fahr/geometry/tet_deformation.h"

namespace fahr::collision {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Six times the signed volume of a tet from flat positions, m^3.
double six_volume(const geometry::Tet& t, const double* x) {
  const Eigen::Vector3d a(x + 3 * std::ptrdiff_t{t[0]});
  const Eigen::Vector3d b = Eigen::Vector3d(x + 3 * std::ptrdiff_t{t[1]}) - a;
  const Eigen::Vector3d c = Eigen::Vector3d(x + 3 * std::ptrdiff_t{t[2]}) - a;
  const Eigen::Vector3d d = Eigen::Vector3d(x + 3 * std::ptrdiff_t{t[3]}) - a;
  return b.dot(c.cross(d));
}

// The smallest singular value of F: the square root of the smallest
// eigenvalue of F^T F (closed form for 3x3, allocation-free).
double smallest_singular_value(const Eigen::Matrix3d& f) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(f.transpose() * f, Eigen::EigenvaluesOnly);
  return std::sqrt(std::max(solver.eigenvalues()[0], 0.0));
}

}  // namespace

SphereState::SphereState(const sphere_layout::SphereLayout& layout,
                         std::span<const double> rest_positions_m)
    : SphereState(layout) {
  if (rest_positions_m.size() < 3 * layout.node_count()) {
    throw std::invalid_argument("sphere state: " + std::to_string(rest_positions_m.size()) +
                                " rest coordinates for " + std::to_string(layout.node_count()) +
                                " nodes");
  }
  const std::vector<geometry::Tet>& tets = layout.tets();
  rest_inverse_.assign(tets.size(), Eigen::Matrix3d::Identity());
  smallest_stretch_.assign(tets.size(), 1.0);
  for (std::size_t t = 0; t < tets.size(); ++t) {
    const Eigen::Matrix3d e = geometry::edge_matrix(rest_positions_m.data(), tets[t]);
    if (!(std::abs(e.determinant()) > 0.0)) {
      throw std::invalid_argument("sphere state: tet " + std::to_string(t) + " is flat at rest");
    }
    rest_inverse_[t] = e.inverse();
  }
}

SphereState::SphereState(const sphere_layout::SphereLayout& layout)
    : centres_m_(layout.size(), Eigen::Vector3d::Zero()),
      radii_m_(layout.size(), 0.0),
      anchors_m_(layout.size(), Eigen::Vector3d::Constant(kNaN)),
      anchor_faces_m_(layout.size(),
                      {Eigen::Vector3d::Constant(kNaN), Eigen::Vector3d::Constant(kNaN),
                       Eigen::Vector3d::Constant(kNaN)}),
      six_volume_m3_(layout.tets().size(), 0.0) {
  reset_to_rest(layout);
}

void SphereState::reset_to_rest(const sphere_layout::SphereLayout& layout) {
  for (std::size_t i = 0; i < layout.size(); ++i) {
    centres_m_[i] = layout.sphere(i).rest_centre_m;
    radii_m_[i] = layout.sphere(i).rest_radius_m;
    const sphere_layout::SurfaceAnchor* anchor = layout.anchor(i);
    if (anchor != nullptr) {
      anchors_m_[i] = anchor->rest_point_m;
      anchor_faces_m_[i] = anchor->rest_face_m;
    }
  }
  ++version_;
}

bool SphereState::update(const sphere_layout::SphereLayout& layout,
                         std::span<const double> positions_m) {
  if (positions_m.size() < 3 * layout.node_count()) return false;
  const double* x = positions_m.data();
  const std::vector<geometry::Tet>& tets = layout.tets();
  // Each tet's volume once: a tet is linked to several spheres.
  for (std::size_t t = 0; t < tets.size(); ++t) six_volume_m3_[t] = six_volume(tets[t], x);
  const bool stretch_rule = !rest_inverse_.empty();
  if (stretch_rule) {
    for (std::size_t t = 0; t < tets.size(); ++t) {
      smallest_stretch_[t] =
          smallest_singular_value(geometry::deformation_gradient(x, tets[t], rest_inverse_[t]));
    }
  }
  for (std::size_t i = 0; i < layout.size(); ++i) {
    const sphere_layout::SphereRecord& s = layout.sphere(i);
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    const auto nodes = layout.nodes(i);
    const auto weights = layout.weights(i);
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      c += weights[k] * Eigen::Vector3d(x + 3 * std::size_t{nodes[k]});
    }
    if (!c.allFinite()) return false;
    double scale = 1.0;
    if (stretch_rule) {
      double smallest = kMaxVolumeScale;
      for (const std::uint32_t t : layout.tets_of(i))
        smallest = std::min(smallest, smallest_stretch_[t]);
      // An inverted tet has a singular value near 0 on the way through: the
      // floor keeps the sphere colliding, as in the volume rule.
      scale = std::max(smallest, kMinVolumeScale);
    } else {
      double six_v = 0.0;
      for (const std::uint32_t t : layout.tets_of(i)) six_v += six_volume_m3_[t];
      const double ratio = six_v / (6.0 * s.rest_linked_volume_m3);
      // cbrt keeps the sphere's volume proportional to its tets' volume.
      scale = ratio > kMinVolumeScale * kMinVolumeScale * kMinVolumeScale
                  ? std::min(std::cbrt(ratio), kMaxVolumeScale)
                  : kMinVolumeScale;
    }
    if (const sphere_layout::SurfaceAnchor* anchor = layout.anchor(i); anchor != nullptr) {
      Eigen::Vector3d a = Eigen::Vector3d::Zero();
      for (std::size_t k = 0; k < 3; ++k) {
        anchor_faces_m_[i][k] = Eigen::Vector3d(x + 3 * std::size_t{anchor->nodes[k]});
        a += anchor->weights[k] * anchor_faces_m_[i][k];
      }
      if (!a.allFinite()) return false;
      anchors_m_[i] = a;
    }
    centres_m_[i] = c;
    radii_m_[i] = s.rest_radius_m * scale;
  }
  ++version_;
  return true;
}

}  // namespace fahr::collision
