// FieldGrid: the single-precision copy of a field's grid reads the same
// trilinear values, its gradient is the interpolant's, and queries through it
// find the same contacts as through the field's own grid.
#include "fahr/collision/field_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "fahr/collision/sphere_query.h"
#include "fahr/collision/sphere_tree.h"
#include "fahr/geometry/signed_distance_field.h"
#include "fahr/sphere_layout/fill_spheres.h"
#include "test_meshes.h"

namespace fahr::collision {
namespace {

geometry::SignedDistanceField ball_field() {
  geometry::SdfOptions options;
  options.cell_size_m = 0.5e-3;
  return geometry::SignedDistanceField(test::icosphere(Eigen::Vector3d::Zero(), 5e-3, 4), options);
}

TEST(FieldGrid, ReadsTheFieldsTrilinearValues) {
  const auto sdf = ball_field();
  const FieldGrid grid(sdf);
  ASSERT_FALSE(grid.empty());
  // Single precision of values of a few centimetres: a few nanometres.
  EXPECT_LT(grid.storage_error_m(), 1e-8);
  // Points inside, near and outside the surface, and beyond the grid.
  for (int i = 0; i < 400; ++i) {
    const double t = 0.37 * i;
    const Eigen::Vector3d p(12e-3 * std::sin(t), 11e-3 * std::cos(1.3 * t),
                            13e-3 * std::sin(0.7 * t + 1.0));
    EXPECT_NEAR(grid.distance(p), sdf.grid_distance(p), grid.storage_error_m() + 1e-12) << i;
    Eigen::Vector3d gradient;
    EXPECT_NEAR(grid.distance_gradient(p, gradient), grid.distance(p), 1e-12);
    // read() and gradient() are the same arithmetic, bit for bit: the query
    // mixes them with distance_gradient and promises the same contacts.
    const FieldGrid::Read cell = grid.read(p);
    EXPECT_EQ(cell.value, grid.distance_gradient(p, gradient)) << i;
    EXPECT_EQ(grid.gradient(cell), gradient) << i;
    // (distance() takes the corner differences in single precision, so it
    // differs from these in the last bits: not compared bit for bit.)
  }
  const Eigen::Vector3d far(0.2, 0.0, 0.0);
  EXPECT_NEAR(grid.distance(far), sdf.grid_distance(far), 1e-8);
  EXPECT_TRUE(
      std::isnan(grid.distance(Eigen::Vector3d(std::numeric_limits<double>::quiet_NaN(), 0, 0))));
  EXPECT_TRUE(std::isinf(FieldGrid().distance(Eigen::Vector3d::Zero())));
  EXPECT_TRUE(
      std::isnan(grid.read(Eigen::Vector3d(0, std::numeric_limits<double>::quiet_NaN(), 0)).value));
  EXPECT_TRUE(std::isinf(FieldGrid().read(Eigen::Vector3d::Zero()).value));
}

TEST(FieldGrid, GradientIsTheInterpolantsAndPointsOutward) {
  const auto sdf = ball_field();
  const FieldGrid grid(sdf);
  const double h = 1e-7;  // well inside one 0.5 mm cell
  for (int i = 0; i < 100; ++i) {
    const double t = 0.61 * i;
    // Points 5.2-7 mm from the centre: outside the ball, within the grid.
    const Eigen::Vector3d dir =
        Eigen::Vector3d(std::sin(t), std::cos(1.7 * t), std::sin(2.3 * t + 0.4)).normalized();
    // The offset keeps p off the grid planes (x = 0 is one), where the
    // interpolant's gradient jumps and a central difference straddles it.
    const Eigen::Vector3d p = (5.2e-3 + 1.8e-3 * (0.5 + 0.5 * std::sin(3.1 * t))) * dir +
                              Eigen::Vector3d(0.0123e-3, 0.0456e-3, 0.0789e-3);
    Eigen::Vector3d gradient;
    grid.distance_gradient(p, gradient);
    Eigen::Vector3d numeric;
    for (int a = 0; a < 3; ++a) {
      const Eigen::Vector3d step = h * Eigen::Vector3d::Unit(a);
      numeric[a] = (grid.distance(p + step) - grid.distance(p - step)) / (2.0 * h);
    }
    // Unless p sits within h of a cell face, the interpolant is smooth there.
    EXPECT_LT((gradient - numeric).norm(), 1e-3) << i;
    EXPECT_GT(gradient.normalized().dot(dir), 0.95) << i;  // outward, near radial
  }
}

TEST(FieldGrid, GridNarrowPhaseFindsTheSameContacts) {
  const geometry::TetMesh mesh = test::block_tet_mesh({0, 0, 0}, {0.01, 0.01, 0.01}, 5);
  sphere_layout::FillSettings fill;
  fill.hugging_sample_spacing_m = 0.4e-3;
  const sphere_layout::SphereLayout layout = sphere_layout::fill_spheres(mesh, fill);
  const SphereState state(layout);
  const SphereTree tree(layout);
  const auto sdf = ball_field();
  const FieldGrid copy(sdf);
  RigidBody plain{1, &sdf, Eigen::Isometry3d::Identity()};
  plain.world_from_body.translation() = Eigen::Vector3d(0.005, 0.005, -0.0048);
  RigidBody fast = plain;
  fast.grid = &copy;
  QuerySettings settings;
  settings.exact_narrow_phase = false;
  settings.candidate_margin_m = 0.25e-3;
  PrePenetrationMemory m1(layout.size()), m2(layout.size());
  ContactBuffer a(4096), b(4096);
  const QueryStats sa = query_spheres(tree, state, plain, settings, m1, a);
  const QueryStats sb = query_spheres(tree, state, fast, settings, m2, b);
  ASSERT_GT(a.size(), 5u);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(sa.spheres_tested, sb.spheres_tested);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].sphere_id, b[i].sphere_id);
    // The distance differs by the storage rounding only. The normal does
    // not: central differences over half a cell against the gradient of the
    // cell's interpolant, on a ball of 20 cells' diameter, measured up to
    // 0.066 rad apart, so the point q = p - d n moves by up to ~0.1 mm (a
    // fifth of a cell): the grid narrow phase's own accuracy (sphere_query.h).
    EXPECT_NEAR(a[i].depth_m, b[i].depth_m, 1e-8);
    EXPECT_GT(a[i].normal.dot(b[i].normal), std::cos(0.1));
    EXPECT_LT((a[i].point_m - b[i].point_m).norm(), 0.15e-3);
  }
  // The exact narrow phase reads the copy only to prune and to bound its
  // triangle search: identical contacts.
  settings.exact_narrow_phase = true;
  a.clear();
  b.clear();
  PrePenetrationMemory m3(layout.size()), m4(layout.size());
  query_spheres(tree, state, plain, settings, m3, a);
  query_spheres(tree, state, fast, settings, m4, b);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].sphere_id, b[i].sphere_id);
    EXPECT_EQ(a[i].depth_m, b[i].depth_m);
  }
}

}  // namespace
}  // namespace fahr::collision
