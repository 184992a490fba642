// Contacts of spheres against rigid bodies in a buffer whose capacity is
// fixed at construction. A full buffer drops further contacts and raises a
// flag: overflow is reported, never a crash or an allocation.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace fahr::collision {

struct SphereContact {
  std::uint32_t sphere_id = 0;  // index into the sphere_layout::SphereLayout
  std::uint32_t body_id = 0;    // RigidBody::id
  // Nearest point of the rigid surface, m, world frame.
  Eigen::Vector3d point_m = Eigen::Vector3d::Zero();
  // Unit normal from that surface toward the sphere centre before penetration
  // (world frame): n = (c - q) / |c - q|.
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();
  // Penetration depth r - (c - q) . n, m: > 0 for a contact, in
  // (-candidate_margin_m, 0] for a candidate (then minus the gap).
  double depth_m = 0.0;
  bool candidate = false;  // near, not touching
  // True when the centre was inside the body and no pre-penetration centre
  // was remembered: the normal is the field's, which can point the wrong way
  // through a thin plate.
  bool normal_without_history = false;
  // The surface's own penetration (ours; set when has_surface): the sphere
  // detects, the deformed surface measures. A sphere keeps its rest radius
  // while the nearly incompressible tissue under a tool is squashed, so its
  // depth_m exceeds the tissue's penetration by the amount it stands out of
  // the deformed surface (docs/design/aist-layout.md; aist_bench detection: 0.6 mm
  // median). surface_point_m, world frame, m: a point of the deformed tissue
  // surface on the sphere's anchor face (sphere_layout::SurfaceAnchor; with
  // QuerySettings::SurfaceProbe::kFacePoint, the default, the point of that
  // face nearest point_m, i.e. the surface where the body touches; with
  // kAnchor the fixed anchor). surface_depth_m = (point_m - surface_point_m)
  // . normal, m: how far that surface point lies behind the body's tangent
  // plane at point_m, > 0 penetrating, <= 0 when the surface there is clear
  // of the body although the sphere touches. Same point, normal and side as
  // depth_m (the pre-penetration normal), so it stays right through a thin
  // plate; exact for a flat face, approximate where the body curves between
  // point_m and surface_point_m (a blade's rim).
  Eigen::Vector3d surface_point_m = Eigen::Vector3d::Zero();
  double surface_depth_m = 0.0;
  // False for a sphere without an anchor (sphere_layout::FillSettings::anchor_gap_m):
  // use depth_m.
  bool has_surface = false;
  // True: only sphere_id, body_id, slot, depth_m and candidate are set yet
  // (QuerySettings::defer_outside_contacts); complete_deferred() works out the
  // rest for the contacts the caller keeps.
  bool deferred = false;
  // The sphere's slot in SphereTree::order() (where the query read it).
  std::uint32_t slot = 0;
};

class ContactBuffer {
 public:
  explicit ContactBuffer(std::size_t capacity) { contacts_.resize(capacity); }

  void clear() noexcept {
    size_ = 0;
    overflowed_ = false;
  }
  // False (and the overflow flag set) when full.
  bool push(const SphereContact& contact) noexcept {
    if (size_ == contacts_.size()) {
      overflowed_ = true;
      return false;
    }
    contacts_[size_++] = contact;
    return true;
  }
  std::size_t size() const { return size_; }
  std::size_t capacity() const { return contacts_.size(); }
  bool overflowed() const { return overflowed_; }
  const SphereContact& operator[](std::size_t i) const { return contacts_[i]; }
  // complete_deferred() fills in the contacts a caller keeps.
  SphereContact& operator[](std::size_t i) { return contacts_[i]; }
  const SphereContact* begin() const { return contacts_.data(); }
  const SphereContact* end() const { return contacts_.data() + size_; }

 private:
  std::vector<SphereContact> contacts_;
  std::size_t size_ = 0;
  bool overflowed_ = false;
};

}  // namespace fahr::collision
