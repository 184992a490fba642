// The detectors' common, independent reference: the FEM tongue driven by node
// contacts. Every boundary node is a contact point of radius 0 (one node,
// weight 1) projected out of the blade's field, with the normal from the
// node's last position outside (the spheres' pre-penetration rule). Neither
// the AIST nor the triangle baseline takes part, so states driven this way
// can be shown to both and judged the same.
#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "fahr/fem/body.h"
#include "fahr/fem/contact_set.h"
#include "fahr/fem/sphere_links.h"
#include "scene.h"

namespace fahr::aist_bench {

class NodeContacts {
 public:
  explicit NodeContacts(const Scene& scene);

  // The contacts of the boundary nodes of `body` with the blade at
  // world_from_blade into `set` (cleared; stamped with the body's step).
  void fill(const fem::Body& body, const Eigen::Isometry3d& world_from_blade, fem::ContactSet& set);
  const fem::SphereLinks& links() const { return links_; }

 private:
  const Scene& scene_;
  fem::SphereLinks links_;
  std::vector<std::uint32_t> nodes_;
  std::vector<Eigen::Vector3d> outside_;  // last position outside the blade, blade frame
  std::vector<bool> remembered_;
};

}  // namespace fahr::aist_bench
