// Node contacts (see node_contacts.h).
#include "node_contacts.h"

#include <algorithm>
#include <span>

namespace fahr::aist_bench {

NodeContacts::NodeContacts(const Scene& scene) : scene_(scene) {
  for (const auto n : scene.surface_to_node) nodes_.push_back(static_cast<std::uint32_t>(n));
  std::sort(nodes_.begin(), nodes_.end());
  nodes_.erase(std::unique(nodes_.begin(), nodes_.end()), nodes_.end());
  const double one = 1.0;
  for (const auto n : nodes_) links_.add_sphere(std::span<const std::uint32_t>(&n, 1), std::span<const double>(&one, 1), 0.0);
  outside_.assign(nodes_.size(), Eigen::Vector3d::Zero());
  remembered_.assign(nodes_.size(), false);
}

void NodeContacts::fill(const fem::Body& body, const Eigen::Isometry3d& world_from_blade, fem::ContactSet& set) {
  set.state_step = body.step_index();
  set.contacts.clear();
  const Eigen::Isometry3d blade_from_world = world_from_blade.inverse();
  for (std::size_t k = 0; k < nodes_.size(); ++k) {
    const Eigen::Vector3d p = blade_from_world * body.position(nodes_[k]);
    const auto s = scene_.blade_sdf.query(p);
    if (s.distance_m > 0.0) {
      outside_[k] = p;
      remembered_[k] = true;
      continue;
    }
    const auto before = remembered_[k] ? scene_.blade_sdf.query(outside_[k]) : s;
    const Eigen::Vector3d from = remembered_[k] ? outside_[k] : p;
    Eigen::Vector3d n = from - before.closest_point_m;
    n = n.norm() > 1e-12 ? Eigen::Vector3d(n.normalized()) : before.normal;
    fem::Contact c;
    c.sphere_id = static_cast<std::uint32_t>(k);
    c.state = fem::ContactState::kActive;
    c.plane_point_m = world_from_blade * before.closest_point_m;
    c.normal = world_from_blade.linear() * n;
    c.penetration_m = -s.distance_m;
    set.contacts.push_back(c);
  }
}

}  // namespace fahr::aist_bench
