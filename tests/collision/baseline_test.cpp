// The triangle baseline: contacts of a block's boundary with a slab, refit
// (never rebuild) after deformation, bad input.
#include <gtest/gtest.h>

#include "fahr/collision/triangle_baseline.h"
#include "test_meshes.h"

namespace fahr::collision {
namespace {

TEST(TriangleBaseline, BlockOnASlabAfterDeformation) {
  const auto mesh = test::block_tet_mesh({0, 0, 0}, {0.01, 0.01, 0.01}, 4);
  std::vector<geometry::Index> surface_to_node;
  const geometry::SurfaceMesh tissue = mesh.boundary_surface(&surface_to_node);
  const geometry::SurfaceMesh slab = test::box_surface({-0.01, -0.01, -0.01}, {0.02, 0.0, 0.02});
  TriangleBaseline baseline(tissue, surface_to_node, slab);
  std::vector<TriangleContact> contacts;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();

  // Deform: every node with y == 0 sinks 0.3 mm into the slab.
  std::vector<double> x;
  std::size_t sunk = 0;
  for (const auto& p : mesh.rest_positions()) {
    const bool bottom = p.y() < 1e-12;
    sunk += bottom && surface_to_node.end() !=
                          std::find(surface_to_node.begin(), surface_to_node.end(),
                                    static_cast<geometry::Index>(&p - &mesh.rest_positions()[0]))
                ? 1
                : 0;
    x.push_back(p.x());
    x.push_back(bottom ? -0.3e-3 : p.y());
    x.push_back(p.z());
  }
  baseline.update(x);
  baseline.collide(pose, contacts);
  EXPECT_EQ(baseline.rebuild_count(), 0u);
  EXPECT_EQ(baseline.refit_count(), 1u);
  std::size_t tissue_contacts = 0;
  for (const auto& c : contacts) {
    if (c.tissue_vertex < 0) continue;
    ++tissue_contacts;
    EXPECT_NEAR(c.depth_m, 0.3e-3, 1e-12);
    EXPECT_NEAR(c.normal.y(), 1.0, 1e-12);
    EXPECT_NEAR(c.point_m.y(), 0.0, 1e-12);
  }
  EXPECT_EQ(tissue_contacts, sunk);
}

// A blade edge poking into a tongue face between its vertices: no tissue
// vertex is inside the tool, so only tool-vertex contacts exist; each acts on
// the nearest corner of the tongue face it is behind, pushing it inward.
TEST(TriangleBaseline, ToolVertexContactsActOnTheNearestFaceCorner) {
  const auto mesh = test::block_tet_mesh({0, 0, 0}, {0.01, 0.01, 0.01}, 4);  // 2.5 mm grid
  std::vector<geometry::Index> surface_to_node;
  const geometry::SurfaceMesh tissue = mesh.boundary_surface(&surface_to_node);
  // A 1.8 mm square peg whose bottom is 0.1 mm below the top face (y = 10 mm).
  const geometry::SurfaceMesh peg =
      test::box_surface({0.0031, 0.0099, 0.0031}, {0.0049, 0.02, 0.0049});
  TriangleBaseline baseline(tissue, surface_to_node, peg);
  std::vector<TriangleContact> contacts;
  baseline.collide(Eigen::Isometry3d::Identity(), contacts);
  ASSERT_FALSE(contacts.empty());
  for (const auto& c : contacts) {
    EXPECT_LT(c.tissue_vertex, 0);
    ASSERT_GE(c.tool_vertex, 0);
    ASSERT_GE(c.acting_tissue_vertex, 0);
    EXPECT_NEAR(c.depth_m, 1e-4, 1e-12);
    EXPECT_NEAR(c.normal.y(), -1.0, 1e-12);
    const Eigen::Vector3d corner =
        tissue.vertices()[static_cast<std::size_t>(c.acting_tissue_vertex)];
    EXPECT_NEAR(corner.y(), 0.01, 1e-12);
    // The 2.5 mm grid vertex nearest the peg's corner.
    EXPECT_NEAR(corner.x(), c.point_m.x() < 0.004 ? 0.0025 : 0.005, 1e-12);
    EXPECT_NEAR(corner.z(), c.point_m.z() < 0.004 ? 0.0025 : 0.005, 1e-12);
  }
}

// A tongue resting 0.5 mm above a 1.2 mm blade plate is behind the plate's
// underside (1.7 mm, within the faces' depth range) but in front of its top
// face, which is nearer: no contact, and with a 1 mm candidate margin a
// candidate 0.5 mm away on the top face.
TEST(TriangleBaseline, AVertexInFrontOfTheNearestFaceIsOutside) {
  const auto mesh = test::block_tet_mesh({0, 0.0005, 0}, {0.01, 0.0105, 0.01}, 4);
  std::vector<geometry::Index> surface_to_node;
  const geometry::SurfaceMesh tissue = mesh.boundary_surface(&surface_to_node);
  const geometry::SurfaceMesh plate = test::box_surface({-0.01, -0.0012, -0.01}, {0.02, 0.0, 0.02});
  TriangleBaseline baseline(tissue, surface_to_node, plate);
  std::vector<TriangleContact> contacts;
  baseline.collide(Eigen::Isometry3d::Identity(), contacts);
  EXPECT_TRUE(contacts.empty()) << contacts.size() << " contacts, the first "
                                << contacts.front().depth_m << " m deep";
  baseline.collide(Eigen::Isometry3d::Identity(), contacts, 1e-3);
  ASSERT_FALSE(contacts.empty());
  for (const auto& c : contacts) {
    EXPECT_NEAR(c.depth_m, -0.5e-3, 1e-12);
    EXPECT_NEAR(c.normal.y(), 1.0, 1e-12);
  }
}

TEST(TriangleBaseline, EmptyOrMismatchedInputIsRefused) {
  const geometry::SurfaceMesh box = test::box_surface({0, 0, 0}, {0.01, 0.01, 0.01});
  EXPECT_THROW(TriangleBaseline(geometry::SurfaceMesh{}, {}, box), std::invalid_argument);
  EXPECT_THROW(TriangleBaseline(box, {0, 1}, box), std::invalid_argument);
}

}  // namespace
}  // namespace fahr::collision
