// Surface anchors of the layout: every sphere's nearest rest boundary point,
// as barycentric weights of its boundary face; the gap that limits which
// spheres get one.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "fahr/sphere_layout/fill_spheres.h"
#include "test_meshes.h"

namespace fahr::sphere_layout {
namespace {

constexpr double kSide = 0.01;  // block edge, m
// A point of a flat box face is exact to rounding.
constexpr double kExactM = 1e-9;

TEST(SurfaceAnchor, EverySphereHasOneOnTheRestBoundary) {
  const geometry::TetMesh mesh = test::block_tet_mesh({0, 0, 0}, {kSide, kSide, kSide}, 5);
  FillSettings s;
  s.hugging_sample_spacing_m = 0.4e-3;
  const SphereLayout layout = fill_spheres(mesh, s);
  ASSERT_EQ(layout.anchor_count(), layout.size());  // the default gap is +infinity
  for (std::size_t i = 0; i < layout.size(); ++i) {
    const SurfaceAnchor* a = layout.anchor(i);
    ASSERT_NE(a, nullptr);
    // On the block's boundary: one coordinate at 0 or kSide.
    const Eigen::Vector3d& p = a->rest_point_m;
    const double to_boundary = std::min(p.minCoeff(), kSide - p.maxCoeff());
    EXPECT_NEAR(to_boundary, 0.0, kExactM) << "sphere " << i;
    // The weights reproduce the point from the face's rest nodes.
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::size_t k = 0; k < 3; ++k) sum += a->weights[k] * mesh.rest_positions()[a->nodes[k]];
    EXPECT_NEAR((sum - p).norm(), 0.0, kExactM);
  }
}

TEST(SurfaceAnchor, GapLimitsWhichSpheresHaveOneAndBadGapsAreRefused) {
  const geometry::TetMesh mesh = test::block_tet_mesh({0, 0, 0}, {kSide, kSide, kSide}, 4);
  FillSettings s;
  s.anchor_gap_m = 0.0;  // only spheres touching the boundary at rest
  const SphereLayout layout = fill_spheres(mesh, s);
  EXPECT_GT(layout.anchor_count(), 0u);
  EXPECT_LT(layout.anchor_count(), layout.size());
  for (std::size_t i = 0; i < layout.size(); ++i) {
    if (layout.anchor(i) == nullptr) continue;
    // |c - p| - r <= gap = 0: the anchor is within the sphere.
    const SphereRecord& sphere = layout.sphere(i);
    EXPECT_LE((layout.anchor(i)->rest_point_m - sphere.rest_centre_m).norm(),
              sphere.rest_radius_m + kExactM)
        << "sphere " << i;
  }
  s.anchor_gap_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(validate_fill_settings(s), std::invalid_argument);
  s.anchor_gap_m = -1e-3;
  EXPECT_THROW(fill_spheres(mesh, s), std::invalid_argument);
}

TEST(SurfaceAnchor, OffLeavesTheSpheresAsTheyAre) {
  const geometry::TetMesh mesh = test::block_tet_mesh({0, 0, 0}, {kSide, kSide, kSide}, 4);
  FillSettings s;
  s.hugging_sample_spacing_m = 0.4e-3;
  const SphereLayout anchored = fill_spheres(mesh, s);
  s.surface_anchors = false;
  const SphereLayout bare = fill_spheres(mesh, s);
  EXPECT_EQ(bare.anchor_count(), 0u);
  ASSERT_EQ(bare.size(), anchored.size());
  for (std::size_t i = 0; i < bare.size(); ++i) {
    EXPECT_EQ(bare.anchor(i), nullptr);
    EXPECT_EQ(bare.sphere(i).rest_centre_m, anchored.sphere(i).rest_centre_m) << "sphere " << i;
    EXPECT_EQ(bare.sphere(i).rest_radius_m, anchored.sphere(i).rest_radius_m) << "sphere " << i;
    EXPECT_TRUE(std::equal(bare.nodes(i).begin(), bare.nodes(i).end(), anchored.nodes(i).begin(),
                           anchored.nodes(i).end()))
        << "sphere " << i;
  }
}

}  // namespace
}  // namespace fahr::sphere_layout
