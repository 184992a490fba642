// Sphere-tree refit and queries against analytic fields (a plane, a sphere, a thin plate).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include "fahr/collision/field_grid.h"
#include "fahr/collision/sphere_query.h"
#include "fahr/collision/sphere_tree.h"
#include "fahr/geometry/signed_distance_field.h"
#include "fahr/sphere_layout/fill_spheres.h"
#include "test_meshes.h"

namespace fahr::collision {
namespace {

// Exact queries of a flat face are exact to rounding.
constexpr double kPlaneToleranceM = 1e-9;
// A 5-times subdivided icosphere of radius 5 mm lies within R (1 - cos(a/2))
// ~ 2 um of the true sphere (a ~ 1.1 degrees between vertices) radially; the
// nearest point on a facet can sit up to about an edge length squared over R
// (~ 20 um) aside from the analytic one.
constexpr double kIcosphereToleranceM = 5e-6;
constexpr double kIcospherePointToleranceM = 25e-6;

struct Block {
  geometry::TetMesh mesh = test::block_tet_mesh({0, 0, 0}, {0.01, 0.01, 0.01}, 5);
  sphere_layout::SphereLayout layout;
  SphereState state;
  SphereTree tree;
  Block() {
    sphere_layout::FillSettings s;
    s.hugging_sample_spacing_m = 0.4e-3;
    layout = sphere_layout::fill_spheres(mesh, s);
    state = SphereState(layout);
    tree = SphereTree(layout);
  }
};

Block& block() {
  static Block b;
  return b;
}

geometry::SignedDistanceField field(const geometry::SurfaceMesh& surface) {
  geometry::SdfOptions options;
  options.cell_size_m = 0.5e-3;
  return geometry::SignedDistanceField(surface, options);
}

TEST(SphereTree, BoxesBoundTheirSpheresAndRefitNeverRebuilds) {
  Block& b = block();
  EXPECT_EQ(b.tree.rebuild_count(), 0u);
  std::vector<double> x;
  for (const auto& p : b.mesh.rest_positions()) {
    // A smooth shear and squash, as a deformation.
    x.push_back(p.x() + 0.2 * p.y());
    x.push_back(0.8 * p.y());
    x.push_back(p.z() + 0.1 * p.x());
  }
  for (int step = 0; step < 10; ++step) {
    ASSERT_TRUE(b.state.update(b.layout, x));
    b.tree.refit(b.state);
  }
  EXPECT_EQ(b.tree.rebuild_count(), 0u);
  EXPECT_EQ(b.tree.refit_count(), 10u);
  for (const auto& node : b.tree.nodes()) {
    if (node.count == 0) continue;
    for (std::int32_t k = 0; k < node.count; ++k) {
      const auto s =
          b.tree.order()[static_cast<std::size_t>(node.first) + static_cast<std::size_t>(k)];
      const Eigen::Vector3d r = Eigen::Vector3d::Constant(b.state.radii_m()[s]);
      EXPECT_TRUE(((b.state.centres_m()[s] - r).array() >= node.box_min_m.array() - 1e-15).all());
      EXPECT_TRUE(((b.state.centres_m()[s] + r).array() <= node.box_max_m.array() + 1e-15).all());
    }
  }
  b.state.reset_to_rest(b.layout);
  b.tree.refit(b.state);
}

TEST(Query, PlaneContactsAreExact) {
  Block& b = block();
  // A slab occupying y < 0.5 mm: its top face is the plane y = h.
  const double h = 0.5e-3;
  const auto slab = field(test::box_surface({-0.01, -0.01, -0.01}, {0.02, h, 0.02}));
  RigidBody body{7, &slab, Eigen::Isometry3d::Identity()};
  PrePenetrationMemory memory(b.layout.size());
  ContactBuffer buffer(4096);
  query_spheres(b.tree, b.state, body, QuerySettings{}, memory, buffer);
  ASSERT_FALSE(buffer.overflowed());
  std::size_t expected = 0;
  for (std::size_t i = 0; i < b.layout.size(); ++i) {
    expected += b.state.centres_m()[i].y() - b.state.radii_m()[i] < h - kPlaneToleranceM ? 1 : 0;
  }
  EXPECT_EQ(buffer.size(), expected);
  ASSERT_GT(buffer.size(), 10u);
  for (const SphereContact& c : buffer) {
    const Eigen::Vector3d centre = b.state.centres_m()[c.sphere_id];
    EXPECT_EQ(c.body_id, 7u);
    EXPECT_NEAR(c.depth_m, b.state.radii_m()[c.sphere_id] - (centre.y() - h), kPlaneToleranceM);
    EXPECT_NEAR(c.normal.y(), 1.0, kPlaneToleranceM);
    EXPECT_NEAR((c.point_m - Eigen::Vector3d(centre.x(), h, centre.z())).norm(), 0.0,
                kPlaneToleranceM);
  }
}

TEST(Query, CandidatesAndGridNarrowPhaseOnAPlane) {
  Block& b = block();
  const double h = 0.5e-3;
  const auto slab = field(test::box_surface({-0.01, -0.01, -0.01}, {0.02, h, 0.02}));
  RigidBody body{7, &slab, Eigen::Isometry3d::Identity()};
  PrePenetrationMemory memory(b.layout.size());
  ContactBuffer buffer(4096);
  QuerySettings settings;
  settings.exact_narrow_phase = false;  // a flat face: the grid is exact there too
  settings.candidate_margin_m = 0.3e-3;
  query_spheres(b.tree, b.state, body, settings, memory, buffer);
  std::size_t candidates = 0;
  for (const SphereContact& c : buffer) {
    const Eigen::Vector3d centre = b.state.centres_m()[c.sphere_id];
    const double depth = b.state.radii_m()[c.sphere_id] - (centre.y() - h);
    EXPECT_NEAR(c.depth_m, depth, 1e-9);
    EXPECT_EQ(c.candidate, depth <= 0.0);
    EXPECT_GT(c.depth_m, -settings.candidate_margin_m);
    EXPECT_NEAR(c.normal.y(), 1.0, 1e-9);
    candidates += c.candidate ? 1 : 0;
  }
  EXPECT_GT(candidates, 0u);
}

// The query skips grid reads where bounds already decide (a leaf proven
// outside is only remembered; an outside sphere too far for a candidate gets
// no normal): every sphere must still come out as the per-sphere rule says.
// Grid narrow phase, fresh memory (so a centre inside has no history): a
// sphere is reported iff r - grid(c) > -candidate margin, with that depth;
// every centre outside within the approach margin is remembered, as is.
TEST(Query, ShortcutsGiveThePerSphereRuleOnTheTongue) {
  const sphere_layout::SphereLayout& layout = test::neonatal_layout();
  SphereState state(layout);
  const SphereTree tree(layout);
  // A slab pressed 3 mm into the tongue's top, tilted, so spheres lie
  // inside, touching, within the margins and far.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);
  for (const Eigen::Vector3d& c : state.centres_m()) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  geometry::SdfOptions options;
  options.cell_size_m = 0.5e-3;
  const geometry::SignedDistanceField slab(
      test::box_surface({lo.x() - 0.01, -0.0012, lo.z() - 0.01},
                        {hi.x() + 0.01, 0.0, hi.z() + 0.01}),
      options);
  const FieldGrid copy(slab);
  RigidBody body{3, &slab, Eigen::Isometry3d::Identity(), &copy};
  body.world_from_body = Eigen::Translation3d(0.0, hi.y() - 3e-3, 0.0) *
                         Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitZ());
  QuerySettings settings;
  settings.exact_narrow_phase = false;
  settings.candidate_margin_m = 1e-3;
  settings.surface_probe = QuerySettings::SurfaceProbe::kNone;
  PrePenetrationMemory memory(layout.size());
  ContactBuffer buffer(layout.size());
  const QueryStats stats = query_spheres(tree, state, body, settings, memory, buffer);
  ASSERT_FALSE(stats.overflowed);
  EXPECT_GT(stats.spheres_remembered, 0u) << "a leaf proven outside: the shortcut ran";
  const double error = 0.8660254037844386 * slab.cell_size_m() + copy.storage_error_m();
  const Eigen::Isometry3d body_from_world = body.world_from_body.inverse();
  std::vector<int> reported(layout.size(), 0);
  for (const SphereContact& c : buffer) {
    ASSERT_EQ(reported[c.sphere_id], 0) << "sphere " << c.sphere_id << " reported twice";
    reported[c.sphere_id] = 1;
    EXPECT_FALSE(c.has_surface) << "kNone gives no surface point";
  }
  std::size_t inside = 0, remembered = 0;
  for (std::size_t slot = 0; slot < tree.order().size(); ++slot) {
    const std::uint32_t id = tree.order()[slot];
    const Eigen::Vector3d p = body_from_world * state.centres_m()[id];
    const double r = state.radii_m()[id];
    const double grid = copy.distance(p);
    const bool expected = r - grid > -settings.candidate_margin_m;
    ASSERT_EQ(reported[id] == 1, expected) << "sphere " << id << " grid " << grid << " r " << r;
    if (expected) {
      const auto it = std::find_if(buffer.begin(), buffer.end(),
                                   [&](const SphereContact& c) { return c.sphere_id == id; });
      EXPECT_EQ(it->depth_m, r - grid) << "sphere " << id;
    }
    inside += grid <= 0.0 ? 1 : 0;
    // Surely within the approach margin (the grid within one error of the
    // distance) and outside: remembered by this query, as it is.
    if (grid > 0.0 &&
        grid + error - r - settings.candidate_margin_m <= settings.approach_margin_m) {
      Eigen::Vector3d centre;
      ASSERT_TRUE(
          memory.recall(static_cast<std::uint32_t>(slot), 1, settings.max_memory_age, centre))
          << id;
      EXPECT_EQ(centre, p) << "sphere " << id;
      ++remembered;
    }
  }
  EXPECT_GT(inside, 0u);
  EXPECT_GT(remembered, 100u);
}

// kNone gives the same contacts as the default probe, without the surface point.
TEST(Query, WithoutASurfaceProbeTheContactsAreTheSame) {
  Block& b = block();
  const auto slab = field(test::box_surface({-0.01, -0.01, -0.01}, {0.02, 0.5e-3, 0.02}));
  RigidBody body{7, &slab, Eigen::Isometry3d::Identity()};
  QuerySettings with, without;
  with.candidate_margin_m = without.candidate_margin_m = 0.3e-3;
  without.surface_probe = QuerySettings::SurfaceProbe::kNone;
  PrePenetrationMemory m1(b.layout.size()), m2(b.layout.size());
  ContactBuffer a(4096), c(4096);
  query_spheres(b.tree, b.state, body, with, m1, a);
  query_spheres(b.tree, b.state, body, without, m2, c);
  ASSERT_EQ(a.size(), c.size());
  ASSERT_GT(a.size(), 0u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].sphere_id, c[i].sphere_id);
    EXPECT_EQ(a[i].depth_m, c[i].depth_m);
    EXPECT_EQ(a[i].normal, c[i].normal);
    EXPECT_TRUE(a[i].has_surface);
    EXPECT_FALSE(c[i].has_surface);
  }
}

TEST(Query, SphereContactsMatchTheAnalyticDistance) {
  Block& b = block();
  const Eigen::Vector3d o(0.005, 0.005, -0.0049);  // the ball reaches 0.1 mm into the block
  const double radius = 5e-3;
  const auto ball = field(test::icosphere(Eigen::Vector3d::Zero(), radius, 5));
  RigidBody body{1, &ball, Eigen::Isometry3d::Identity()};
  body.world_from_body.translation() = o;
  PrePenetrationMemory memory(b.layout.size());
  ContactBuffer buffer(4096);
  query_spheres(b.tree, b.state, body, QuerySettings{}, memory, buffer);
  ASSERT_GT(buffer.size(), 5u);
  for (const SphereContact& c : buffer) {
    const Eigen::Vector3d centre = b.state.centres_m()[c.sphere_id];
    const double d = (centre - o).norm() - radius;
    ASSERT_GT(d, 0.0) << "no centre is inside the ball in this case";
    EXPECT_NEAR(c.depth_m, b.state.radii_m()[c.sphere_id] - d, kIcosphereToleranceM);
    EXPECT_NEAR(c.normal.dot((centre - o).normalized()), 1.0, 1e-3);
    EXPECT_NEAR((c.point_m - (o + radius * (centre - o).normalized())).norm(), 0.0,
                kIcospherePointToleranceM);
  }
  // Every sphere that overlaps the ball by more than the tessellation error is reported.
  std::size_t expected = 0;
  for (std::size_t i = 0; i < b.layout.size(); ++i) {
    const double d = (b.state.centres_m()[i] - o).norm() - radius;
    expected += b.state.radii_m()[i] - d > kIcosphereToleranceM ? 1 : 0;
  }
  EXPECT_GE(buffer.size(), expected);
}

// The haptic tick keeps the k deepest contacts: the deepest-first walk finds
// exactly those (the same depths as the full query's k deepest) and tests
// fewer spheres. A ball pressed 2 mm into the block touches many spheres at
// many depths, as a blade on the tongue does.
TEST(Query, DeepestOnlyFindsTheDeepestContactsOfTheFullQuery) {
  Block& b = block();
  const Eigen::Vector3d o(0.004, 0.006, -0.003);
  const auto ball = field(test::icosphere(Eigen::Vector3d::Zero(), 5e-3, 4));
  RigidBody body{1, &ball, Eigen::Isometry3d::Identity()};
  body.world_from_body.translation() = o;
  QuerySettings settings;
  settings.exact_narrow_phase = false;
  settings.candidate_margin_m = 1e-3;
  PrePenetrationMemory full_memory(b.layout.size());
  ContactBuffer full(8192);
  const QueryStats full_stats = query_spheres(b.tree, b.state, body, settings, full_memory, full);
  const std::size_t k = 16;
  ASSERT_GT(full.size(), 4 * k);
  settings.deepest_only = k;
  PrePenetrationMemory memory(b.layout.size());
  ContactBuffer limited(8192);
  const QueryStats stats = query_spheres(b.tree, b.state, body, settings, memory, limited);
  ASSERT_GE(limited.size(), k);
  EXPECT_LT(stats.spheres_tested, full_stats.spheres_tested / 2);
  auto deepest = [&](const ContactBuffer& buffer) {
    std::vector<double> depths;
    for (const SphereContact& c : buffer) depths.push_back(c.depth_m);
    std::sort(depths.begin(), depths.end(), std::greater<>());
    depths.resize(k);
    return depths;
  };
  EXPECT_EQ(deepest(limited), deepest(full));
}

TEST(Query, NormalComesFromThePrePenetrationCentreThroughAThinPlate) {
  Block& b = block();
  // A 1 mm plate below the block, rising through it in 0.1 mm steps: once a
  // centre is past the plate's mid-plane, the field's normal points down, but
  // the remembered centre above keeps the contact normal up (+y).
  const auto plate = field(test::box_surface({-0.01, -0.0005, -0.01}, {0.02, 0.0005, 0.02}));
  RigidBody body{2, &plate, Eigen::Isometry3d::Identity()};
  PrePenetrationMemory memory(b.layout.size());
  ContactBuffer buffer(4096);
  std::size_t deep = 0;
  for (int step = 0; step <= 26; ++step) {  // the plate's bottom stays above the lowest centres
    body.world_from_body.translation() = Eigen::Vector3d(0, -0.002 + 1e-4 * step, 0);
    buffer.clear();
    query_spheres(b.tree, b.state, body, QuerySettings{}, memory, buffer);
    for (const SphereContact& c : buffer) {
      EXPECT_FALSE(c.normal_without_history);
      EXPECT_GT(c.normal.y(), 0.99) << "step " << step << " sphere " << c.sphere_id;
      const double plate_top = body.world_from_body.translation().y() + 0.0005;
      deep += b.state.centres_m()[c.sphere_id].y() < plate_top - 0.0005 ? 1 : 0;
      EXPECT_NEAR(
          c.depth_m,
          b.state.radii_m()[c.sphere_id] - (b.state.centres_m()[c.sphere_id].y() - plate_top),
          kPlaneToleranceM);
    }
  }
  EXPECT_GT(deep, 0u) << "some centres passed the mid-plane";
}

// The narrow phase's triangle search, bounded by the sphere's last nearest
// point (kept in the memory), gives the answer of an unbounded search (a
// fresh memory every query); the grid shortcut for flat fields
// (flat_gradient_tolerance) stays within its stated error. Contacts whose
// centre lies inside the body are left out: their normal depends on the
// memory's pre-penetration centre, which a fresh memory does not have.
void expect_same_contacts(const RigidBody& body, const Eigen::Vector3d& step, int steps,
                          double flat_tolerance, double tolerance_m, double point_tolerance_m,
                          bool (*centre_inside)(const RigidBody&, const Eigen::Vector3d&)) {
  Block& b = block();
  QuerySettings hinted;
  hinted.flat_gradient_tolerance = flat_tolerance;
  PrePenetrationMemory memory(b.layout.size());
  ContactBuffer plain_buffer(4096), buffer(4096);
  RigidBody moving = body;
  std::size_t compared = 0;
  for (int k = 0; k < steps; ++k) {
    moving.world_from_body.translation() = body.world_from_body.translation() + k * step;
    PrePenetrationMemory fresh(b.layout.size());
    plain_buffer.clear();
    buffer.clear();
    query_spheres(b.tree, b.state, moving, QuerySettings{}, fresh, plain_buffer);
    query_spheres(b.tree, b.state, moving, hinted, memory, buffer);
    std::size_t j = 0;
    for (std::size_t i = 0; i < plain_buffer.size(); ++i) {
      const SphereContact& plain = plain_buffer[i];
      while (j < buffer.size() && buffer[j].sphere_id != plain.sphere_id) ++j;
      if (centre_inside(moving, b.state.centres_m()[plain.sphere_id])) continue;
      if (j == buffer.size()) {
        // Only the grid shortcut may drop a contact, and only a graze.
        EXPECT_GT(flat_tolerance, 0.0) << "step " << k << " sphere " << plain.sphere_id;
        EXPECT_LT(std::abs(plain.depth_m), tolerance_m);
        j = 0;
        continue;
      }
      EXPECT_NEAR(buffer[j].depth_m, plain.depth_m, tolerance_m) << "step " << k;
      EXPECT_LT((buffer[j].point_m - plain.point_m).norm(), point_tolerance_m) << "step " << k;
      ++compared;
    }
  }
  EXPECT_GT(compared, 20u);
}

bool inside_plate(const RigidBody& body, const Eigen::Vector3d& c) {
  const Eigen::Vector3d p = body.world_from_body.inverse() * c;
  return std::abs(p.x()) < 0.004 && std::abs(p.y()) < 0.0005 && std::abs(p.z()) < 0.004;
}

bool inside_ball(const RigidBody& body, const Eigen::Vector3d& c) {
  return (c - body.world_from_body.translation()).norm() < 5e-3;
}

TEST(Query, BoundedSearchGivesTheUnboundedAnswerOnAPlate) {
  // A 1 mm plate rising into the block: faces, edges and the mid-plane ridge.
  const auto plate = field(test::box_surface({-0.004, -0.0005, -0.004}, {0.004, 0.0005, 0.004}));
  RigidBody body{2, &plate, Eigen::Isometry3d::Identity()};
  body.world_from_body.translation() = Eigen::Vector3d(0.003, -0.002, 0.005);
  expect_same_contacts(body, Eigen::Vector3d(0.0, 1e-4, 1e-5), 25, 0.0, 1e-12, 1e-12, inside_plate);
}

TEST(Query, BoundedSearchGivesTheUnboundedAnswerOnABall) {
  const auto ball = field(test::icosphere(Eigen::Vector3d::Zero(), 5e-3, 5));
  RigidBody body{1, &ball, Eigen::Isometry3d::Identity()};
  body.world_from_body.translation() = Eigen::Vector3d(0.005, 0.005, -0.0052);
  expect_same_contacts(body, Eigen::Vector3d(0.0, 0.0, 2e-5), 25, 0.0, 1e-12, 1e-12, inside_ball);
}

TEST(Query, FlatGridShortcutStaysWithinItsErrorOnABall) {
  // Depth: h^2 / (8 rho) with h = 0.5 mm, rho >= 5 mm, about 6 um. The point
  // p - d n also carries the grid normal's angle error times d (1-2 mm).
  const auto ball = field(test::icosphere(Eigen::Vector3d::Zero(), 5e-3, 5));
  RigidBody body{1, &ball, Eigen::Isometry3d::Identity()};
  body.world_from_body.translation() = Eigen::Vector3d(0.005, 0.005, -0.0052);
  expect_same_contacts(body, Eigen::Vector3d(0.0, 0.0, 2e-5), 25, 1e-3, 6e-6, 50e-6, inside_ball);
}

TEST(Query, OverflowIsAFlagAndANanPoseTouchesNothing) {
  Block& b = block();
  const auto slab = field(test::box_surface({-0.01, -0.01, -0.01}, {0.02, 0.005, 0.02}));
  RigidBody body{3, &slab, Eigen::Isometry3d::Identity()};
  PrePenetrationMemory memory(b.layout.size());
  ContactBuffer small(4);
  const QueryStats stats = query_spheres(b.tree, b.state, body, QuerySettings{}, memory, small);
  EXPECT_TRUE(stats.overflowed);
  EXPECT_TRUE(small.overflowed());
  EXPECT_EQ(small.size(), 4u);
  EXPECT_GT(stats.contacts, 4u);

  body.world_from_body.translation().x() = std::numeric_limits<double>::quiet_NaN();
  ContactBuffer buffer(64);
  const QueryStats nan_stats =
      query_spheres(b.tree, b.state, body, QuerySettings{}, memory, buffer);
  EXPECT_EQ(buffer.size(), 0u);
  EXPECT_TRUE(nan_stats.body_skipped);
}

TEST(Query, FarBodyIsSkippedAtTheRoot) {
  Block& b = block();
  const auto ball = field(test::icosphere(Eigen::Vector3d::Zero(), 0.003, 2));
  RigidBody body{4, &ball, Eigen::Isometry3d::Identity()};
  body.world_from_body.translation() = Eigen::Vector3d(0.1, 0, 0);
  PrePenetrationMemory memory(b.layout.size());
  ContactBuffer buffer(64);
  const QueryStats stats = query_spheres(b.tree, b.state, body, QuerySettings{}, memory, buffer);
  EXPECT_TRUE(stats.body_skipped);
  EXPECT_EQ(stats.nodes_visited, 1u);
  EXPECT_EQ(stats.spheres_tested, 0u);
}

TEST(Query, OpenToolSurfaceIsRefusedByTheField) {
  auto box = test::box_surface({0, 0, 0}, {0.01, 0.01, 0.01});
  std::vector<geometry::Triangle> open(box.triangles().begin(), box.triangles().end() - 1);
  const geometry::SurfaceMesh surface(box.vertices(), open);
  EXPECT_THROW(geometry::SignedDistanceField(surface, geometry::SdfOptions{}),
               std::invalid_argument);
}

}  // namespace
}  // namespace fahr::collision
