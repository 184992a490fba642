// The tick path allocates nothing: state update, refit and queries.
#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "fahr/collision/sphere_query.h"
#include "fahr/collision/sphere_tree.h"
#include "fahr/geometry/signed_distance_field.h"
#include "test_meshes.h"

namespace fahr::collision {
namespace {

TEST(Allocation, UpdateRefitAndQueryAllocateNothing) {
  const auto& mesh = fahr::test::neonatal_tongue();
  const sphere_layout::SphereLayout& layout = fahr::test::neonatal_layout();
  SphereState state(layout);
  SphereTree tree(layout);
  std::vector<double> rest;
  for (const auto& p : mesh.rest_positions()) rest.insert(rest.end(), {p.x(), p.y(), p.z()});
  SphereState stretch_state(layout, rest);  // the smallest-stretch radius rule
  geometry::SdfOptions options;
  options.cell_size_m = 1e-3;
  const geometry::SignedDistanceField slab(
      fahr::test::box_surface({-0.06, -0.04, -0.02}, {0.0, -0.005, 0.02}), options);
  const FieldGrid slab_grid(slab);
  RigidBody body{0, &slab, Eigen::Isometry3d::Identity()};
  PrePenetrationMemory memory(layout.size());
  ContactBuffer buffer(256);  // small on purpose: overflow must not allocate either
  std::vector<double> x;
  for (const auto& p : mesh.rest_positions()) {
    for (int a = 0; a < 3; ++a) x.push_back(p[a]);
  }

  // Both narrow phases, with candidates and a skin: every branch of the path.
  QuerySettings exact, grid, searched;
  grid.exact_narrow_phase = false;
  searched.flat_gradient_tolerance = 0.0;  // every narrow-phase sphere searches the triangles
  searched.surface_probe = QuerySettings::SurfaceProbe::kAnchor;  // both surface probes
  grid.candidate_margin_m = 0.25e-3;
  grid.contact_skin_m = 0.1e-3;
  std::size_t contacts = 0, with_surface = 0;
  fahr::test::AllocationCounter counter;
  for (int tick = 0; tick < 50; ++tick) {
    x[1] -= 1e-5;  // a node moves: a new FEM state every tick
    state.update(layout, x);
    stretch_state.update(layout, x);
    tree.refit(tick % 2 == 0 ? state : stretch_state);
    body.world_from_body.translation().y() = 1e-4 * tick;
    buffer.clear();
    // Every fourth tick through the body's FieldGrid.
    body.grid = tick % 4 == 3 ? &slab_grid : nullptr;
    const QuerySettings& settings = tick % 3 == 0 ? exact : (tick % 3 == 1 ? grid : searched);
    query_spheres(tree, tick % 2 == 0 ? state : stretch_state, body, settings, memory, buffer);
    contacts += buffer.size();
    for (const SphereContact& c : buffer) with_surface += c.has_surface ? 1 : 0;
  }
  EXPECT_EQ(counter.count(), 0);
  EXPECT_GT(contacts, 0u) << "the slab touches the tongue: the narrow phase ran";
  EXPECT_EQ(with_surface, contacts) << "every sphere of the default layout has a surface anchor";
  EXPECT_EQ(tree.rebuild_count(), 0u);
}

TEST(Allocation, CounterSeesAnAllocation) {
  long allocations = 0;
  {
    fahr::test::AllocationCounter counter;
    // A direct call: a new-expression may be elided by the optimiser.
    void* p = ::operator new(16);
    allocations = counter.count();
    ::operator delete(p);
  }
  EXPECT_EQ(allocations, 1);
}

}  // namespace
}  // namespace fahr::collision
