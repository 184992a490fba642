// Layouts of several bodies joined into one (the haptic service's tissue of
// several deformable bodies): every sphere keeps its record, links and
// anchor, with node and tet indices moved past the bodies before it, so a
// sphere's centre computed on the joined node array is its centre on its
// own body's.
#include <gtest/gtest.h>

#include <array>
#include <stdexcept>
#include <vector>

#include "fahr/sphere_layout/fill_spheres.h"
#include "test_meshes.h"

namespace fahr::sphere_layout {
namespace {

// sum_i w_i x_i over a node array of 3 doubles per node.
Eigen::Vector3d centre(const SphereLayout& layout, std::size_t sphere,
                       const std::vector<Eigen::Vector3d>& nodes) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  const auto n = layout.nodes(sphere);
  const auto w = layout.weights(sphere);
  for (std::size_t i = 0; i < n.size(); ++i) c += w[i] * nodes[n[i]];
  return c;
}

TEST(Concatenate, EachSphereKeepsItsBodysLinksAndAnchor) {
  const geometry::TetMesh a = test::block_tet_mesh({0, 0, 0}, {0.01, 0.01, 0.01}, 4);
  const geometry::TetMesh b = test::block_tet_mesh({0.03, 0, 0}, {0.012, 0.008, 0.01}, 5);
  const SphereLayout la = fill_spheres(a, FillSettings{});
  const SphereLayout lb = fill_spheres(b, FillSettings{});
  const std::array<const SphereLayout*, 2> layouts{&la, &lb};
  const std::array<std::size_t, 2> offsets{0, a.node_count()};
  const SphereLayout joined = concatenate(layouts, offsets);

  ASSERT_EQ(joined.size(), la.size() + lb.size());
  EXPECT_EQ(joined.node_count(), a.node_count() + b.node_count());
  EXPECT_EQ(joined.tets().size(), la.tets().size() + lb.tets().size());
  std::vector<Eigen::Vector3d> nodes = a.rest_positions();
  nodes.insert(nodes.end(), b.rest_positions().begin(), b.rest_positions().end());
  // Moved bodies: each sphere follows its own body's nodes only.
  for (std::size_t n = 0; n < a.node_count(); ++n) nodes[n] += Eigen::Vector3d(0, 0.002, 0);
  std::vector<Eigen::Vector3d> moved_a(nodes.begin(),
                                       nodes.begin() + static_cast<std::ptrdiff_t>(a.node_count()));
  for (std::size_t s = 0; s < joined.size(); ++s) {
    const bool first = s < la.size();
    const SphereLayout& own = first ? la : lb;
    const std::size_t local = first ? s : s - la.size();
    const Eigen::Vector3d expected =
        first ? centre(la, local, moved_a) : centre(lb, local, b.rest_positions());
    EXPECT_LT((centre(joined, s, nodes) - expected).norm(), 1e-15) << "sphere " << s;
    EXPECT_EQ(joined.sphere(s).rest_radius_m, own.sphere(local).rest_radius_m);
    EXPECT_EQ(joined.tets_of(s).size(), own.tets_of(local).size());
    // The linked tets are the body's own, moved past the tets before it.
    for (std::size_t t = 0; t < own.tets_of(local).size(); ++t) {
      const geometry::Tet& got = joined.tets()[joined.tets_of(s)[t]];
      const geometry::Tet& want = own.tets()[own.tets_of(local)[t]];
      for (int k = 0; k < 4; ++k) {
        EXPECT_EQ(static_cast<std::size_t>(got[k]),
                  static_cast<std::size_t>(want[k]) + (first ? 0 : a.node_count()));
      }
    }
    const SurfaceAnchor* anchor = joined.anchor(s);
    const SurfaceAnchor* own_anchor = own.anchor(local);
    ASSERT_EQ(anchor == nullptr, own_anchor == nullptr) << "sphere " << s;
    if (anchor != nullptr) {
      for (int k = 0; k < 3; ++k)
        EXPECT_EQ(anchor->nodes[k], own_anchor->nodes[k] + (first ? 0 : a.node_count()));
    }
  }
}

TEST(Concatenate, OneLayoutIsAnEqualCopyAndBadOffsetsAreRefused) {
  const geometry::TetMesh a = test::block_tet_mesh({0, 0, 0}, {0.01, 0.01, 0.01}, 4);
  const SphereLayout la = fill_spheres(a, FillSettings{});
  const std::array<const SphereLayout*, 1> one{&la};
  const std::array<std::size_t, 1> zero{0};
  EXPECT_EQ(concatenate(one, zero).fingerprint(), la.fingerprint());
  const std::array<std::size_t, 1> shifted{3};
  EXPECT_THROW(concatenate(one, shifted), std::invalid_argument);
  const std::array<const SphereLayout*, 2> two{&la, &la};
  EXPECT_THROW(concatenate(two, zero), std::invalid_argument);
}

}  // namespace
}  // namespace fahr::sphere_layout
