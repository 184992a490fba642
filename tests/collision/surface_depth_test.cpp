// Surface anchors and the surface depth (SphereContact::surface_depth_m): a
// tet block squashed at constant volume keeps its spheres' radii (volume
// rule), so they stand out of its flattened top; pressed by a plane, the
// spheres' depth overstates the penetration while the surface depth gives
// the top face's true penetration.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "fahr/collision/sphere_query.h"
#include "fahr/collision/sphere_tree.h"
#include "fahr/geometry/signed_distance_field.h"
#include "fahr/sphere_layout/fill_spheres.h"
#include "test_meshes.h"

namespace fahr::collision {
namespace {

constexpr double kSide = 0.01;           // block edge, m
constexpr double kSquash = 0.8;          // y scale; x and z by 1/sqrt(kSquash): volume kept
constexpr double kPenetration = 0.3e-3;  // of the flattened top face into the plane, m
// A flat face's points and the exact narrow phase on a box face are exact
// to rounding.
constexpr double kExactM = 1e-9;

struct SquashedBlock {
  geometry::TetMesh mesh = test::block_tet_mesh({0, 0, 0}, {kSide, kSide, kSide}, 5);
  sphere_layout::SphereLayout layout;
  std::vector<double> squashed;
  double top_m = kSquash * kSide;  // the deformed top face, y
  SquashedBlock() {
    sphere_layout::FillSettings s;
    s.hugging_sample_spacing_m = 0.4e-3;
    layout = sphere_layout::fill_spheres(mesh, s);
    const double widen = 1.0 / std::sqrt(kSquash);
    for (const auto& p : mesh.rest_positions()) {
      squashed.insert(squashed.end(), {0.5 * kSide + widen * (p.x() - 0.5 * kSide), kSquash * p.y(),
                                       0.5 * kSide + widen * (p.z() - 0.5 * kSide)});
    }
  }
};

const SquashedBlock& squashed_block() {
  static const SquashedBlock b;
  return b;
}

// A plate over the block whose underside is the plane y = top - kPenetration.
geometry::SignedDistanceField pressing_plate(double underside_m) {
  geometry::SdfOptions options;
  options.cell_size_m = 0.5e-3;
  return geometry::SignedDistanceField(
      test::box_surface({-0.01, underside_m, -0.01}, {0.02, 0.02, 0.02}), options);
}

TEST(SurfaceAnchor, TheStateHasNoAnchorWhereTheLayoutHasNone) {
  const geometry::TetMesh mesh = test::block_tet_mesh({0, 0, 0}, {kSide, kSide, kSide}, 4);
  sphere_layout::FillSettings s;
  s.anchor_gap_m = 0.0;  // only spheres touching the boundary at rest
  const sphere_layout::SphereLayout layout = sphere_layout::fill_spheres(mesh, s);
  ASSERT_GT(layout.anchor_count(), 0u);
  ASSERT_LT(layout.anchor_count(), layout.size());
  SphereState state(layout);
  for (std::size_t i = 0; i < layout.size(); ++i) {
    EXPECT_EQ(layout.anchor(i) == nullptr, std::isnan(state.anchors_m()[i].x()));
  }
}

// The services turn anchors off (they use the sphere depth): the same
// spheres and contacts, no surface point, nothing gathered per state.
TEST(SurfaceAnchor, OffGivesTheSameContactsWithoutASurface) {
  const SquashedBlock& b = squashed_block();
  const geometry::TetMesh mesh = test::block_tet_mesh({0, 0, 0}, {kSide, kSide, kSide}, 5);
  sphere_layout::FillSettings s;
  s.hugging_sample_spacing_m = 0.4e-3;
  s.surface_anchors = false;
  const sphere_layout::SphereLayout bare = sphere_layout::fill_spheres(mesh, s);
  ASSERT_EQ(bare.size(), b.layout.size());
  EXPECT_EQ(bare.anchor_count(), 0u);
  const auto plate = pressing_plate(b.top_m - kPenetration);
  RigidBody body{3, &plate, Eigen::Isometry3d::Identity()};
  std::vector<SphereContact> found[2];
  int k = 0;
  for (const sphere_layout::SphereLayout* layout : {&b.layout, &bare}) {
    SphereState state(*layout);
    ASSERT_TRUE(state.update(*layout, b.squashed));
    SphereTree tree(*layout);
    tree.refit(state);
    PrePenetrationMemory memory(layout->size());
    ContactBuffer buffer(4096);
    query_spheres(tree, state, body, QuerySettings{}, memory, buffer);
    for (const SphereContact& c : buffer) found[k].push_back(c);
    ++k;
  }
  ASSERT_EQ(found[0].size(), found[1].size());
  ASSERT_GT(found[0].size(), 10u);
  for (std::size_t i = 0; i < found[0].size(); ++i) {
    EXPECT_EQ(found[0][i].sphere_id, found[1][i].sphere_id);
    EXPECT_EQ(found[0][i].depth_m, found[1][i].depth_m);
    EXPECT_TRUE(found[0][i].has_surface);
    EXPECT_FALSE(found[1][i].has_surface);
  }
}

TEST(SurfaceDepth, IsTheFlattenedSurfacesTruePenetrationWhereTheSphereDepthIsNot) {
  const SquashedBlock& b = squashed_block();
  SphereState state(b.layout);  // the volume rule: radii stay at rest under a volume-keeping squash
  ASSERT_TRUE(state.update(b.layout, b.squashed));
  SphereTree tree(b.layout);
  tree.refit(state);
  const auto plate = pressing_plate(b.top_m - kPenetration);
  RigidBody body{3, &plate, Eigen::Isometry3d::Identity()};
  for (const auto probe :
       {QuerySettings::SurfaceProbe::kFacePoint, QuerySettings::SurfaceProbe::kAnchor}) {
    QuerySettings settings;
    settings.surface_probe = probe;
    PrePenetrationMemory memory(b.layout.size());
    ContactBuffer buffer(4096);
    query_spheres(tree, state, body, settings, memory, buffer);
    ASSERT_FALSE(buffer.overflowed());
    ASSERT_GT(buffer.size(), 10u);
    std::size_t on_top = 0;
    double sphere_error = 0.0;
    for (const SphereContact& c : buffer) {
      ASSERT_TRUE(c.has_surface);
      // The sphere depth: the spheres keep their rest radius and stand out of
      // the top face, so they report more than the surface's penetration.
      sphere_error = std::max(sphere_error, std::abs(c.depth_m - kPenetration));
      // No surface point of the block lies deeper than its top face.
      EXPECT_LE(c.surface_depth_m, kPenetration + kExactM);
      EXPECT_NEAR(c.surface_depth_m, (c.point_m - c.surface_point_m).dot(c.normal), kExactM);
      if (probe == QuerySettings::SurfaceProbe::kAnchor) {
        EXPECT_NEAR((c.surface_point_m - state.anchors_m()[c.sphere_id]).norm(), 0.0, kExactM);
      }
      if (std::abs(c.surface_point_m.y() - b.top_m) > kExactM) continue;  // a side face's point
      ++on_top;
      EXPECT_NEAR(c.surface_depth_m, kPenetration, kExactM) << "sphere " << c.sphere_id;
    }
    // Most touching spheres are anchored on the top face; the sphere depth is
    // off by far more than the 0.2 mm target.
    EXPECT_GT(2 * on_top, buffer.size());
    EXPECT_GT(sphere_error, 0.2e-3);
  }
}

TEST(SurfaceDepth, IsZeroOrLessWhereTheSurfaceIsClearOfTheBody) {
  const SquashedBlock& b = squashed_block();
  SphereState state(b.layout);
  ASSERT_TRUE(state.update(b.layout, b.squashed));
  SphereTree tree(b.layout);
  tree.refit(state);
  // The plane just above the flattened top: the spheres standing out of it
  // still touch, the surface does not.
  const auto plate = pressing_plate(b.top_m + 0.05e-3);
  RigidBody body{3, &plate, Eigen::Isometry3d::Identity()};
  PrePenetrationMemory memory(b.layout.size());
  ContactBuffer buffer(4096);
  query_spheres(tree, state, body, QuerySettings{}, memory, buffer);
  ASSERT_GT(buffer.size(), 0u) << "the spheres stand out of the squashed top";
  for (const SphereContact& c : buffer) {
    EXPECT_GT(c.depth_m, 0.0);
    EXPECT_LE(c.surface_depth_m, -0.05e-3 + kExactM);
  }
}

}  // namespace
}  // namespace fahr::collision
