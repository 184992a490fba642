// The glottic view score (fahr::glottic_view): exact on shapes whose answer
// is known, and on the neonatal scene within a fraction of a point of a
// pixel count of the same view by a z-buffer (tools/glottic_score), over
// eyes that see all, part and none of the opening, the tongue at rest and
// pressed.
#include "fahr/glottic_view/glottic_view.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "fahr/geometry/surface_loader.h"
#include "fahr/geometry/surface_mesh.h"
#include "fahr/geometry/triangle_bvh.h"
#include "fahr/glottic_view/scene_view.h"
#include "fahr/scene/load_scene.h"
#include "pixel_view.h"

namespace fahr::glottic_view {
namespace {

using Eigen::Vector3d;

// A closed box, outward triangles.
geometry::SurfaceMesh box(const Vector3d& lo, const Vector3d& hi) {
  std::vector<Vector3d> v;
  for (int i = 0; i < 8; ++i) {
    v.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  }
  const std::vector<geometry::Triangle> t = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6},
                                             {0, 1, 4}, {1, 5, 4}, {2, 6, 3}, {3, 6, 7},
                                             {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
  return {v, t};
}

const Opening kDisc{Vector3d::Zero(), Vector3d::UnitY(), 0.004};

TEST(TriangleBvhSegment, AgreesWithEveryTriangleTested) {
  const auto scene = scene::load_scene(FAHR_NEONATAL_SCENE);
  const auto larynx = scene->find_body("larynx_trachea");
  ASSERT_TRUE(larynx);
  const auto& body = scene->bodies[*larynx];
  const auto local = geometry::load_surface(body.mesh_path, body.mesh_scale);
  const geometry::TriangleBvh tree(local);
  std::mt19937 rng(7);
  // Segments through the region of the laryngeal inlet and the trachea.
  std::uniform_real_distribution<double> x(-0.080, -0.045), y(-0.090, -0.010), z(-0.010, 0.010);
  int hits = 0;
  for (int i = 0; i < 4000; ++i) {
    const Vector3d a(x(rng), y(rng), z(rng));
    const Vector3d b(x(rng), y(rng), z(rng));
    const bool fast = tree.segment_hits(a, b);
    ASSERT_EQ(fast, tree.segment_hits_brute_force(a, b)) << "segment " << i;
    hits += fast ? 1 : 0;
  }
  // Both outcomes occur, so the agreement means something.
  EXPECT_GT(hits, 400);
  EXPECT_LT(hits, 3600);
  // Axis-parallel segments (infinite inverse direction components).
  EXPECT_TRUE(
      tree.segment_hits(Vector3d(-0.062, 0.01, 0.0), Vector3d(-0.062, -0.12, 0.0)) ==
      tree.segment_hits_brute_force(Vector3d(-0.062, 0.01, 0.0), Vector3d(-0.062, -0.12, 0.0)));
}

TEST(GlotticView, AnOpenViewIsWholeAndTheBackIsNone) {
  GlotticView view(kDisc);
  const auto seen = view.score(Vector3d(0.01, 0.1, 0.0), std::nullopt, {});
  EXPECT_TRUE(seen.facing);
  EXPECT_DOUBLE_EQ(seen.visible_share, 1.0);
  EXPECT_EQ(seen.samples, 1024u);
  const auto behind = view.score(Vector3d(0.0, -0.1, 0.0), std::nullopt, {});
  EXPECT_FALSE(behind.facing);
  EXPECT_DOUBLE_EQ(behind.visible_share, 0.0);
}

TEST(GlotticView, APlateOverHalfTheOpeningHidesHalf) {
  GlotticView view(kDisc);
  // A thin plate over x < 0, 5 mm above the disc; the eye straight above.
  view.add_rigid(box(Vector3d(-0.01, 0.005, -0.01), Vector3d(0.0, 0.0051, 0.01)));
  const auto s = view.score(Vector3d(0.0, 0.2, 0.0), std::nullopt, {});
  EXPECT_NEAR(s.visible_share, 0.5, 0.015);
}

TEST(GlotticView, AnEllipseIsSampledOverItsOwnArea) {
  // 4 mm along x, 1 mm across (z): a plate over z > 0.5 mm hides the part of
  // the unit disc above y = 0.5, (acos(0.5) - 0.5 sqrt(0.75)) / pi of it; over
  // a 4 mm disc it would hide the part above y = 0.125.
  const Opening ellipse{kDisc.centre_m, kDisc.normal, 0.004, Vector3d(1.0, 0.2, 0.0), 0.001};
  GlotticView view(ellipse);
  for (const auto& p : view.sample_points()) {
    const Vector3d d = p - ellipse.centre_m;
    EXPECT_NEAR(d.y(), 0.0, 1e-15);
    EXPECT_LE(std::pow(d.x() / 0.004, 2) + std::pow(d.z() / 0.001, 2), 1.0 + 1e-12);
  }
  view.add_rigid(box(Vector3d(-0.01, 0.005, 0.0005), Vector3d(0.01, 0.0051, 0.01)));
  const auto s = view.score(Vector3d(0.0, 0.2, 0.0), std::nullopt, {});
  const double hidden = (std::acos(0.5) - 0.5 * std::sqrt(0.75)) / M_PI;
  EXPECT_NEAR(s.visible_share, 1.0 - hidden, 0.015);
  GlotticView disc(kDisc);
  disc.add_rigid(box(Vector3d(-0.01, 0.005, 0.0005), Vector3d(0.01, 0.0051, 0.01)));
  EXPECT_LT(disc.score(Vector3d(0.0, 0.2, 0.0), std::nullopt, {}).visible_share, 0.7);
}

TEST(GlotticView, TheToolOccludesWhereItIsPosed) {
  GlotticView view(kDisc);
  // A tool whose box sits 10-20 mm along its +x: posed over the disc it
  // hides it; turned away, it does not.
  view.set_tool(box(Vector3d(0.010, -0.01, -0.01), Vector3d(0.020, 0.01, 0.01)));
  Eigen::Isometry3d over = Eigen::Isometry3d::Identity();
  over.translation() = Vector3d(-0.015, 0.05, 0.0);
  EXPECT_DOUBLE_EQ(view.score(Vector3d(0.0, 0.2, 0.0), over, {}).visible_share, 0.0);
  Eigen::Isometry3d away = over;
  away.translation() = Vector3d(0.05, 0.05, 0.0);
  EXPECT_DOUBLE_EQ(view.score(Vector3d(0.0, 0.2, 0.0), away, {}).visible_share, 1.0);
  EXPECT_DOUBLE_EQ(view.score(Vector3d(0.0, 0.2, 0.0), std::nullopt, {}).visible_share, 1.0);
}

TEST(GlotticView, BadInputIsRefusedByName) {
  EXPECT_THROW(GlotticView(Opening{Vector3d::Zero(), Vector3d::UnitY(), 0.0}),
               std::invalid_argument);
  EXPECT_THROW(GlotticView(Opening{Vector3d::Zero(), Vector3d::Zero(), 0.004}),
               std::invalid_argument);
  // An ellipse wider across than along, or with its axis along the normal.
  EXPECT_THROW(
      GlotticView(Opening{Vector3d::Zero(), Vector3d::UnitY(), 0.002, Vector3d::UnitX(), 0.003}),
      std::invalid_argument);
  EXPECT_THROW(
      GlotticView(Opening{Vector3d::Zero(), Vector3d::UnitY(), 0.004, Vector3d::UnitY(), 0.001}),
      std::invalid_argument);
  GlotticView view(kDisc);
  view.add_deformable({{0, 1, 2}});
  const std::vector<Vector3d> two = {Vector3d::Zero(), Vector3d::UnitX()};
  const std::span<const Vector3d> short_span(two);
  EXPECT_THROW(view.score(Vector3d(0, 0.1, 0), std::nullopt, std::span(&short_span, 1)),
               std::invalid_argument);
  std::vector<Vector3d> nan = {Vector3d::Zero(), Vector3d::UnitX(),
                               Vector3d(std::numeric_limits<double>::quiet_NaN(), 0, 0)};
  const std::span<const Vector3d> nan_span(nan);
  EXPECT_THROW(view.score(Vector3d(0, 0.1, 0), std::nullopt, std::span(&nan_span, 1)),
               std::invalid_argument);
  EXPECT_THROW(view.add_deformable({{0, -1, 2}}), std::invalid_argument);
}

// An eye `distance` from the opening's centre, turned `deg` from its normal
// towards the mouth (+x) in the mid-sagittal plane, `lateral` to the side.
Vector3d eye_around(const Opening& o, double deg, double distance, double lateral) {
  const Vector3d anterior = Vector3d::UnitZ().cross(o.normal).normalized() * -1.0;
  const double a = deg * M_PI / 180.0;
  return o.centre_m + distance * (std::cos(a) * o.normal + std::sin(a) * anterior) +
         lateral * Vector3d::UnitZ();
}

TEST(GlotticViewOnTheScene, RaysAgreeWithAPixelCountOfTheSameView) {
  const auto scene = scene::load_scene(FAHR_NEONATAL_SCENE);
  SceneGlotticView view = glottic_view_from_scene(*scene);
  const auto meshes = glottic_score::load_scene_meshes(*scene);
  ASSERT_EQ(view.deformable_rest_m.size(), 1u);
  // The tongue pressed: every node above the floor of the mouth 4 mm lower,
  // a crude stand-in for a blade's indentation that still moves the view.
  std::vector<Vector3d> pressed = view.deformable_rest_m[0];
  for (auto& p : pressed) p.y() -= 0.004 * std::clamp((p.y() + 0.012) / 0.02, 0.0, 1.0);
  int partial = 0, none = 0, whole = 0;
  double worst = 0.0;
  for (const auto* tongue : {&view.deformable_rest_m[0], &pressed}) {
    for (const double lateral : {0.0, 0.004}) {
      for (const double deg : {-70.0, -40.0, -10.0, 0.0, 10.0, 14.0, 17.0, 19.0, 21.0, 30.0}) {
        glottic_score::ViewInput in;
        in.eye_m = eye_around(view.view.opening(), deg, 0.02, lateral);
        in.deformable_positions.emplace_back(*tongue);
        const std::span<const Vector3d> soft(*tongue);
        const double rays =
            view.view.score(in.eye_m, std::nullopt, std::span(&soft, 1)).visible_share;
        const double pixels =
            glottic_score::pixel_share(meshes, view.view.opening(), in, 300).visible_share;
        worst = std::max(worst, std::abs(rays - pixels));
        EXPECT_NEAR(rays, pixels, 0.02) << "eye at " << deg << " deg, " << lateral << " m aside";
        partial += (rays > 0.05 && rays < 0.95) ? 1 : 0;
        none += rays == 0.0 ? 1 : 0;
        whole += rays == 1.0 ? 1 : 0;
      }
    }
  }
  // The sweep covers every regime, so agreement is not the trivial 0 = 0.
  EXPECT_GE(partial, 3);
  EXPECT_GE(none, 3);
  EXPECT_GE(whole, 1);
  std::printf(
      "glottic view, rays against pixels: largest difference %.2f points, %d partial, "
      "%d hidden, %d whole views\n",
      100.0 * worst, partial, none, whole);
}

}  // namespace
}  // namespace fahr::glottic_view
