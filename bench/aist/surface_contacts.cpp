// Surface contacts (see surface_contacts.h).
#include "surface_contacts.h"

#include <algorithm>
#include <array>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>

namespace fahr::aist_bench {
namespace {

// The box is widened by this so that it holds the blade with room to
// spare: a point outside it is outside the blade whatever the rounding of
// the blade's bounds, and is skipped without a field query.
constexpr double kBoxMarginM = 1e-3;

// Adds a point; the weights are built to sum to 1, so a refusal is a bug
// that would shift every later point's id.
void add_point(fem::SphereLinks& links, std::span<const std::uint32_t> nodes,
               std::span<const double> weights) {
  const std::string error = links.add_sphere(nodes, weights, 0.0);
  if (!error.empty()) throw std::logic_error("surface contacts: " + error);
}

}  // namespace

SurfaceContacts::SurfaceContacts(const Scene& scene, int subdivision) : scene_(scene) {
  if (subdivision < 1) throw std::invalid_argument("surface contacts: subdivision must be >= 1");
  std::vector<std::uint32_t> nodes;
  for (const auto n : scene.surface_to_node) nodes.push_back(static_cast<std::uint32_t>(n));
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  const double one = 1.0;
  for (const auto n : nodes)
    add_point(links_, std::span<const std::uint32_t>(&n, 1), std::span<const double>(&one, 1));

  const double n_inv = 1.0 / subdivision;
  const auto node_of = [&](geometry::Index v) {
    return static_cast<std::uint32_t>(scene.surface_to_node[v]);
  };
  std::set<std::pair<std::uint32_t, std::uint32_t>> edges_done;
  for (const auto& t : scene.boundary.triangles()) {
    const std::array<std::uint32_t, 3> face{node_of(t[0]), node_of(t[1]), node_of(t[2])};
    // Each edge's inner points once, whichever face reaches it first.
    for (int k = 0; k < 3; ++k) {
      const auto a = std::min(face[k], face[(k + 1) % 3]);
      const auto b = std::max(face[k], face[(k + 1) % 3]);
      if (!edges_done.insert({a, b}).second) continue;
      for (int m = 1; m < subdivision; ++m) {
        const std::array<std::uint32_t, 2> ends{a, b};
        const std::array<double, 2> w{1.0 - m * n_inv, m * n_inv};
        add_point(links_, ends, w);
      }
    }
    // The face's inner points: i + j + k = N, all >= 1.
    for (int i = 1; i < subdivision; ++i) {
      for (int j = 1; i + j < subdivision; ++j) {
        const int k = subdivision - i - j;
        const std::array<double, 3> w{i * n_inv, j * n_inv, k * n_inv};
        add_point(links_, face, w);
      }
    }
  }
  blade_box_ = Eigen::AlignedBox3d(scene.blade.bounds_min(), scene.blade.bounds_max());
  blade_box_.min().array() -= kBoxMarginM;
  blade_box_.max().array() += kBoxMarginM;
  outside_.assign(links_.size(), Eigen::Vector3d::Zero());
  remembered_.assign(links_.size(), false);
}

void SurfaceContacts::fill(const fem::Body& body, const Eigen::Isometry3d& world_from_blade,
                           fem::ContactSet& set) {
  set.state_step = body.step_index();
  set.contacts.clear();
  const Eigen::Isometry3d blade_from_world = world_from_blade.inverse();
  for (std::size_t k = 0; k < links_.size(); ++k) {
    const Eigen::Vector3d p = blade_from_world * links_.centre(k, body.positions_m().data());
    if (!blade_box_.contains(p)) {
      outside_[k] = p;
      remembered_[k] = true;
      continue;
    }
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
