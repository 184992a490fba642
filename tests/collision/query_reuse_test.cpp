// Work the query leaves out must not change what it gives: the deferred
// narrow phase (the haptic tick completes only the rows it keeps) and the
// grid floors (reads skipped for spheres a bound from the last query keeps
// beyond the margins), each against the query that does the work, bit for
// bit, over a blade-like slab moving through the neonatal tongue.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <vector>

#include "fahr/collision/deepest_contacts.h"
#include "fahr/collision/field_grid.h"
#include "fahr/collision/sphere_query.h"
#include "fahr/collision/sphere_tree.h"
#include "fahr/geometry/signed_distance_field.h"
#include "test_meshes.h"

namespace fahr::collision {
namespace {

// The haptic tick's row budget (msg::MAX_COMPLIANCE_SPHERES).
constexpr std::size_t kRows = 64;
constexpr int kQueries = 100;

// A 1.2 mm slab (the blade's thickness) over the whole tongue, slightly
// tilted, starting 2 mm above its highest centre and sinking 30 um a query while it slides
// 50 um (a hand at 5 cm/s, ticks at 1 kHz), so spheres approach, touch, go
// inside (recalling their memory) and fall behind.
struct Press {
  const sphere_layout::SphereLayout& layout = test::neonatal_layout();
  SphereState state{layout};
  SphereTree tree{layout};
  geometry::SignedDistanceField slab;
  FieldGrid copy;
  double top = -1e300;
  Press() {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);
    for (const Eigen::Vector3d& c : state.centres_m()) {
      lo = lo.cwiseMin(c);
      hi = hi.cwiseMax(c);
    }
    top = hi.y();
    geometry::SdfOptions options;
    options.cell_size_m = 0.5e-3;
    slab = geometry::SignedDistanceField(test::box_surface({lo.x() - 0.02, -0.0012, lo.z() - 0.01},
                                                           {hi.x() + 0.02, 0.0, hi.z() + 0.01}),
                                         options);
    copy = FieldGrid(slab);
  }
  RigidBody body(int query) const {
    RigidBody b{3, &slab, Eigen::Isometry3d::Identity(), &copy};
    b.world_from_body = Eigen::Translation3d(50e-6 * query, top + 2e-3 - 30e-6 * query, 0.0) *
                        Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitZ());
    return b;
  }
};

Press& press() {
  static Press p;
  return p;
}

// The haptic service's settings (services/haptic/src/haptic_loop.cpp).
QuerySettings service_settings() {
  QuerySettings s;
  s.exact_narrow_phase = false;
  s.candidate_margin_m = 1e-3;
  s.surface_probe = QuerySettings::SurfaceProbe::kNone;
  return s;
}

void expect_same_memory(const PrePenetrationMemory& a, const PrePenetrationMemory& b,
                        std::uint64_t query, std::uint64_t max_age) {
  for (std::uint32_t slot = 0; slot < a.size(); ++slot) {
    Eigen::Vector3d ca, cb;
    const bool ra = a.recall(slot, query, max_age, ca), rb = b.recall(slot, query, max_age, cb);
    ASSERT_EQ(ra, rb) << "slot " << slot;
    if (ra) {
      ASSERT_EQ(ca, cb) << "slot " << slot;
    }
  }
}

TEST(QueryReuse, DeferredContactsGiveTheSameRowsBitForBit) {
  Press& p = press();
  QuerySettings full = service_settings();
  QuerySettings deferred = full;
  deferred.defer_outside_contacts = true;
  PrePenetrationMemory full_memory(p.layout.size()), deferred_memory(p.layout.size());
  ContactBuffer a(4096), b(4096);
  std::vector<std::uint32_t> rows_a(4096), rows_b(4096);
  std::size_t over_budget = 0, deferred_rows = 0, inside_rows = 0;
  for (int q = 0; q < kQueries; ++q) {
    const RigidBody body = p.body(q);
    a.clear();
    b.clear();
    const QueryStats sa = query_spheres(p.tree, p.state, body, full, full_memory, a);
    const QueryStats sb = query_spheres(p.tree, p.state, body, deferred, deferred_memory, b);
    ASSERT_FALSE(sa.overflowed);
    ASSERT_EQ(sa.contacts, sb.contacts);
    ASSERT_EQ(a.size(), b.size());
    const std::size_t ka = select_deepest(a, kRows, rows_a);
    const std::size_t kb = select_deepest(b, kRows, rows_b);
    ASSERT_EQ(ka, kb);
    for (std::size_t r = 0; r < kb; ++r) {
      deferred_rows += b[rows_b[r]].deferred ? 1 : 0;
      inside_rows += b[rows_b[r]].deferred ? 0 : 1;  // centre inside: complete from the query
    }
    complete_deferred(p.tree, body, deferred, b, rows_b.data(), kb);
    over_budget += a.size() > kRows ? 1 : 0;
    for (std::size_t r = 0; r < ka; ++r) {
      const SphereContact& x = a[rows_a[r]];
      const SphereContact& y = b[rows_b[r]];
      ASSERT_EQ(x.sphere_id, y.sphere_id) << "query " << q << " row " << r;
      EXPECT_EQ(x.point_m, y.point_m) << "query " << q << " row " << r;
      EXPECT_EQ(x.normal, y.normal) << "query " << q << " row " << r;
      EXPECT_EQ(x.depth_m, y.depth_m);
      EXPECT_EQ(x.candidate, y.candidate);
      EXPECT_EQ(x.normal_without_history, y.normal_without_history);
      EXPECT_FALSE(y.deferred);
    }
    expect_same_memory(full_memory, deferred_memory, static_cast<std::uint64_t>(q) + 1,
                       full.max_memory_age);
  }
  EXPECT_GT(over_budget, 5u) << "the slab touches more spheres than the rows take";
  EXPECT_GT(deferred_rows, 100u) << "kept rows were completed after the selection";
  std::printf(
      "%zu queries over the row budget, %zu rows completed after the selection, %zu from the "
      "query\n",
      over_budget, deferred_rows, inside_rows);
  EXPECT_GT(inside_rows, 0u) << "rows whose depth came from the pre-penetration memory";
}

TEST(QueryReuse, GridFloorsGiveTheSameContactsAndMemoryBitForBit) {
  Press& p = press();
  const QuerySettings settings = service_settings();
  PrePenetrationMemory with(p.layout.size()), without(p.layout.size());
  ContactBuffer a(4096), b(4096);
  std::uint64_t bounded = 0, tested_with = 0, tested_without = 0;
  for (int q = 0; q < kQueries; ++q) {
    const RigidBody body = p.body(q);
    a.clear();
    b.clear();
    without.forget_grid_floors();
    const QueryStats sa = query_spheres(p.tree, p.state, body, settings, with, a);
    const QueryStats sb = query_spheres(p.tree, p.state, body, settings, without, b);
    EXPECT_EQ(sb.spheres_bounded, 0u);
    bounded += sa.spheres_bounded;
    tested_with += sa.spheres_tested;
    tested_without += sb.spheres_tested;
    ASSERT_EQ(sa.spheres_tested + sa.spheres_bounded, sb.spheres_tested);
    ASSERT_EQ(a.size(), b.size()) << "query " << q;
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a[i].sphere_id, b[i].sphere_id) << "query " << q;
      EXPECT_EQ(a[i].point_m, b[i].point_m);
      EXPECT_EQ(a[i].normal, b[i].normal);
      EXPECT_EQ(a[i].depth_m, b[i].depth_m);
      EXPECT_EQ(a[i].normal_without_history, b[i].normal_without_history);
    }
    expect_same_memory(with, without, static_cast<std::uint64_t>(q) + 1, settings.max_memory_age);
  }
  EXPECT_GT(bounded, 0u);
  std::printf("grid reads with floors %llu, without %llu\n",
              static_cast<unsigned long long>(tested_with),
              static_cast<unsigned long long>(tested_without));
  EXPECT_LT(tested_with, tested_without * 3 / 4) << "the floors skip a good share of the reads";
}

}  // namespace
}  // namespace fahr::collision
