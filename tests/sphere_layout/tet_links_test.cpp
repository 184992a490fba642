// Links of each sphere to its tets: node weights >= 0 summing to 1 that
// reproduce the rest centre, the linked tets and their rest volume, hugging
// spheres carried by the surface, and the layout's own checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>
#include <stdexcept>
#include <vector>

#include "fahr/sphere_layout/fill_spheres.h"
#include "test_meshes.h"

namespace fahr::sphere_layout {
namespace {

// Weights are formed from a handful of terms in double precision: the centre
// they give matches the stored one to rounding of millimetre coordinates.
constexpr double kCentreToleranceM = 1e-12;

void expect_links_valid(const SphereLayout& layout, const geometry::TetMesh& mesh,
                        std::size_t max_linked_tets) {
  for (std::size_t i = 0; i < layout.size(); ++i) {
    double sum = 0.0;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    const auto nodes = layout.nodes(i);
    const auto weights = layout.weights(i);
    for (std::size_t k = 0; k < nodes.size(); ++k) {
      ASSERT_GE(weights[k], 0.0) << "sphere " << i;
      sum += weights[k];
      c += weights[k] * mesh.rest_positions()[nodes[k]];
    }
    ASSERT_NEAR(sum, 1.0, kWeightSumTolerance) << "sphere " << i;
    ASSERT_LT((c - layout.sphere(i).rest_centre_m).norm(), kCentreToleranceM) << "sphere " << i;
    // Distinct tets of the mesh, at least one, at most the setting; the
    // stored rest volume is theirs.
    const auto tets = layout.tets_of(i);
    ASSERT_GE(tets.size(), 1u) << "sphere " << i;
    ASSERT_LE(tets.size(), max_linked_tets) << "sphere " << i;
    const std::set<std::uint32_t> distinct(tets.begin(), tets.end());
    ASSERT_EQ(distinct.size(), tets.size()) << "sphere " << i;
    double volume = 0.0;
    for (const std::uint32_t t : tets) {
      ASSERT_LT(t, mesh.tet_count()) << "sphere " << i;
      volume += mesh.rest_data()[t].volume_m3;
    }
    ASSERT_NEAR(layout.sphere(i).rest_linked_volume_m3, volume, 1e-12 * volume) << "sphere " << i;
  }
}

TEST(TetLinks, WeightsSumToOneAndReproduceTheCentreOnABlock) {
  const auto mesh = test::block_tet_mesh({0, 0, 0}, {0.01, 0.01, 0.01}, 6);
  FillSettings settings;
  settings.hugging_sample_spacing_m = 0.4e-3;
  const SphereLayout layout = fill_spheres(mesh, settings);
  ASSERT_GT(layout.size(), 20u);
  expect_links_valid(layout, mesh, static_cast<std::size_t>(settings.max_linked_tets));
}

TEST(TetLinks, WeightsSumToOneAndReproduceTheCentreOnTheTongue) {
  const SphereLayout& layout = test::neonatal_layout();
  expect_links_valid(layout, test::neonatal_tongue(),
                     static_cast<std::size_t>(FillSettings{}.max_linked_tets));
  // The weights of most grid spheres spread over more than one tet's four nodes.
  std::size_t spread = 0, grid = 0;
  for (std::size_t i = 0; i < layout.size(); ++i) {
    if (layout.sphere(i).origin != SphereOrigin::kGrid) continue;
    ++grid;
    spread += layout.nodes(i).size() > 4 ? 1 : 0;
  }
  EXPECT_GT(spread, grid / 2);
}

TEST(TetLinks, FewerLinkedTetsWhenTheSettingSaysSo) {
  const auto mesh = test::block_tet_mesh({0, 0, 0}, {0.01, 0.01, 0.01}, 4);
  FillSettings settings;
  settings.hugging_sample_spacing_m = 0.4e-3;
  settings.max_linked_tets = 2;
  const SphereLayout layout = fill_spheres(mesh, settings);
  expect_links_valid(layout, mesh, 2);
  const auto most = std::max_element(
      layout.spheres().begin(), layout.spheres().end(),
      [](const SphereRecord& a, const SphereRecord& b) { return a.tet_count < b.tet_count; });
  EXPECT_EQ(most->tet_count, 2u) << "an inner sphere overlaps more than two tets";
}

// The share of a sphere's weight on boundary nodes.
double surface_share(const SphereLayout& layout, std::size_t sphere,
                     const std::vector<bool>& on_boundary) {
  double share = 0.0;
  const auto nodes = layout.nodes(sphere);
  const auto weights = layout.weights(sphere);
  for (std::size_t k = 0; k < nodes.size(); ++k) share += on_boundary[nodes[k]] ? weights[k] : 0.0;
  return share;
}

TEST(TetLinks, HuggingSpheresAreCarriedByTheSurfaceNodes) {
  // With hugging_anchor_depth_factor k the tangent face's nodes carry 1 - 1/k
  // of a hugging sphere's weight (less only where the deeper point leaves the
  // body and k is lowered); with k = 1 the sphere hangs on the tet holding its
  // centre, often an inner one.
  const auto& mesh = test::neonatal_tongue();
  std::vector<geometry::Index> surface_to_node;
  mesh.boundary_surface(&surface_to_node);
  std::vector<bool> on_boundary(mesh.node_count(), false);
  for (const auto n : surface_to_node) on_boundary[static_cast<std::size_t>(n)] = true;
  const SphereLayout& anchored = test::neonatal_layout();
  ASSERT_GT(FillSettings{}.hugging_anchor_depth_factor, 2.0);
  const double full = 1.0 - 1.0 / FillSettings{}.hugging_anchor_depth_factor;
  std::size_t hugging = 0, carried = 0;
  for (std::size_t i = 0; i < anchored.size(); ++i) {
    if (anchored.sphere(i).origin != SphereOrigin::kHugging) continue;
    ++hugging;
    carried += surface_share(anchored, i, on_boundary) >= full - 1e-9 ? 1 : 0;
  }
  ASSERT_GT(hugging, 1000u);
  EXPECT_GT(carried, hugging * 9 / 10) << carried << " of " << hugging;

  FillSettings plain;
  plain.hugging_anchor_depth_factor = 1.0;
  const SphereLayout unanchored = fill_spheres(mesh, plain);
  std::size_t plain_carried = 0, plain_hugging = 0;
  for (std::size_t i = 0; i < unanchored.size(); ++i) {
    if (unanchored.sphere(i).origin != SphereOrigin::kHugging) continue;
    ++plain_hugging;
    plain_carried += surface_share(unanchored, i, on_boundary) >= full - 1e-9 ? 1 : 0;
  }
  EXPECT_LT(plain_carried, plain_hugging / 2) << plain_carried << " of " << plain_hugging;
}

TEST(TetLinks, TheLayoutRefusesWeightsThatDoNotSumToOne) {
  // One sphere on one tet of four nodes.
  SphereRecord s;
  s.rest_radius_m = 1e-3;
  s.link_count = 4;
  s.tet_count = 1;
  const std::vector<std::uint32_t> nodes{0, 1, 2, 3};
  const std::vector<geometry::Tet> tets{{0, 1, 2, 3}};
  EXPECT_NO_THROW(SphereLayout({s}, nodes, {0.25, 0.25, 0.25, 0.25}, {0}, tets, 4, 0, 1e-3));
  EXPECT_THROW(SphereLayout({s}, nodes, {0.25, 0.25, 0.25, 0.2}, {0}, tets, 4, 0, 1e-3),
               std::invalid_argument);
  EXPECT_THROW(SphereLayout({s}, nodes, {0.5, 0.5, 0.25, -0.25}, {0}, tets, 4, 0, 1e-3),
               std::invalid_argument);
  EXPECT_THROW(SphereLayout({s}, {0, 1, 2, 4}, {0.25, 0.25, 0.25, 0.25}, {0}, tets, 4, 0, 1e-3),
               std::invalid_argument)
      << "node 4 of a 4-node mesh";
}

}  // namespace
}  // namespace fahr::sphere_layout
