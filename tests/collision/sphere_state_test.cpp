// SphereState's radius rules under a uniaxial squash: the volume rule scales
// radii by the cube root of the volume change, the smallest-stretch rule by
// the squash itself, so the sphere stays inside its rest sphere's image.
#include "fahr/collision/sphere_state.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "fahr/sphere_layout/fill_spheres.h"
#include "test_meshes.h"

namespace fahr::collision {
namespace {

TEST(SphereState, SmallestStretchRuleFollowsTheSquash) {
  const geometry::TetMesh mesh = test::block_tet_mesh({0, 0, 0}, {0.01, 0.01, 0.01}, 4);
  const sphere_layout::SphereLayout layout =
      sphere_layout::fill_spheres(mesh, sphere_layout::FillSettings{});
  std::vector<double> rest, squashed;
  constexpr double kSquash = 0.7;  // y scaled by 0.7, x and z kept: volume 0.7
  for (const auto& p : mesh.rest_positions()) {
    rest.insert(rest.end(), {p.x(), p.y(), p.z()});
    squashed.insert(squashed.end(), {p.x(), kSquash * p.y(), p.z()});
  }
  SphereState volume(layout);
  SphereState stretch(layout, rest);
  // At rest both give the rest radii.
  for (std::size_t i = 0; i < layout.size(); ++i) {
    EXPECT_NEAR(stretch.radii_m()[i], layout.sphere(i).rest_radius_m, 1e-12);
  }
  ASSERT_TRUE(volume.update(layout, squashed));
  ASSERT_TRUE(stretch.update(layout, squashed));
  for (std::size_t i = 0; i < layout.size(); ++i) {
    const double r0 = layout.sphere(i).rest_radius_m;
    EXPECT_NEAR(volume.radii_m()[i], r0 * std::cbrt(kSquash), 1e-9 * r0);
    EXPECT_NEAR(stretch.radii_m()[i], r0 * kSquash, 1e-9 * r0);
    EXPECT_NEAR((stretch.centres_m()[i] - volume.centres_m()[i]).norm(), 0.0, 1e-15);
  }
  // A rigid rotation keeps the radii under both rules.
  std::vector<double> turned;
  const double c = std::cos(0.5), s = std::sin(0.5);
  for (const auto& p : mesh.rest_positions())
    turned.insert(turned.end(), {c * p.x() - s * p.y(), s * p.x() + c * p.y(), p.z()});
  ASSERT_TRUE(stretch.update(layout, turned));
  for (std::size_t i = 0; i < layout.size(); ++i) {
    EXPECT_NEAR(stretch.radii_m()[i], layout.sphere(i).rest_radius_m,
                1e-9 * layout.sphere(i).rest_radius_m);
  }
}

TEST(SphereState, SmallestStretchRuleRefusesShortRestPositions) {
  const geometry::TetMesh mesh = test::block_tet_mesh({0, 0, 0}, {0.01, 0.01, 0.01}, 2);
  const sphere_layout::SphereLayout layout =
      sphere_layout::fill_spheres(mesh, sphere_layout::FillSettings{});
  const std::vector<double> too_short(3, 0.0);
  EXPECT_THROW(SphereState(layout, too_short), std::invalid_argument);
}

TEST(SphereState, RestStateCentresFollowTheNodes) {
  // A rigid translation of every node moves every centre by the same amount
  // and keeps every radius.
  const auto& mesh = test::neonatal_tongue();
  const sphere_layout::SphereLayout& layout = test::neonatal_layout();
  const Eigen::Vector3d shift(0.002, -0.001, 0.0005);
  std::vector<double> x;
  for (const auto& p : mesh.rest_positions()) {
    for (int a = 0; a < 3; ++a) x.push_back(p[a] + shift[a]);
  }
  SphereState state(layout);
  ASSERT_TRUE(state.update(layout, x));
  for (std::size_t i = 0; i < layout.size(); ++i) {
    ASSERT_LT((state.centres_m()[i] - layout.sphere(i).rest_centre_m - shift).norm(), 1e-12);
    ASSERT_NEAR(state.radii_m()[i], layout.sphere(i).rest_radius_m, 1e-12);
  }
  x[0] = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(state.update(layout, x)) << "a NaN position is refused";
}

}  // namespace
}  // namespace fahr::collision
