// TetMesh and SurfaceMesh: rest data, boundary, quality statistics, topology;
// the tet deformation gradient.
#include "fahr/geometry/tet_mesh.h"

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <vector>

#include "fahr/geometry/tet_deformation.h"
#include "test_support.h"

namespace fahr::geometry {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRoundoff = 1e-12;  // relative: a few hundred ulps of sums over a few hundred tets

TEST(TetMesh, CubeRestDataAndBoundary) {
  const int n = 3;
  const double edge = 0.01;
  const TetMesh mesh = test::cube_tets(n, edge);
  EXPECT_EQ(mesh.tet_count(), 6u * n * n * n);
  const double volume = std::pow(n * edge, 3);
  EXPECT_NEAR(mesh.quality().total_volume_m3, volume, kRoundoff * volume);
  EXPECT_EQ(mesh.boundary_faces().size(), 6u * 2u * n * n);
  for (std::size_t t = 0; t < mesh.tet_count(); ++t) {
    const Tet& tet = mesh.tets()[t];
    const auto& x = mesh.rest_positions();
    const double six_volume = edge_matrix(x[tet[0]], x[tet[1]], x[tet[2]], x[tet[3]]).determinant();
    EXPECT_GT(mesh.rest_data()[t].volume_m3, 0.0);
    EXPECT_NEAR(six_volume, 6.0 * mesh.rest_data()[t].volume_m3,
                kRoundoff * mesh.rest_data()[t].volume_m3);
  }
  // Outward faces: the boundary encloses the cube's volume with a positive sign.
  const SurfaceMesh surface = mesh.boundary_surface();
  EXPECT_TRUE(surface.is_closed());
  EXPECT_TRUE(surface.is_manifold());
  EXPECT_NEAR(surface.enclosed_volume_m3(), volume, kRoundoff * volume);
}

// F = Ds Dm^-1 of an affine map x -> A x + b is A for every tet, whatever
// its shape; from flat positions as the FEM keeps them.
TEST(TetDeformation, GradientOfAnAffineMapIsItsMatrix) {
  const TetMesh mesh = test::cube_tets(2, 0.01);
  Eigen::Matrix3d a;
  a << 1.1, 0.2, -0.05, 0.0, 0.8, 0.1, 0.03, -0.2, 1.3;
  const Eigen::Vector3d b(0.01, -0.02, 0.005);
  std::vector<double> flat;
  for (const Eigen::Vector3d& x : mesh.rest_positions()) {
    const Eigen::Vector3d y = a * x + b;
    flat.insert(flat.end(), {y.x(), y.y(), y.z()});
  }
  const auto& x = mesh.rest_positions();
  for (const Tet& tet : mesh.tets()) {
    const Eigen::Matrix3d dm_inverse =
        edge_matrix(x[tet[0]], x[tet[1]], x[tet[2]], x[tet[3]]).inverse();
    const Eigen::Matrix3d f = deformation_gradient(flat.data(), tet, dm_inverse);
    EXPECT_TRUE(f.isApprox(a, 1e-12)) << f;
  }
}

TEST(TetMesh, KuhnTetQuality) {
  const TetMesh mesh = test::cube_tets(1, 1.0);
  const TetQualityStats& q = mesh.quality();
  // Kuhn tets of a cube have dihedral angles of 45, 60 and 90 degrees.
  EXPECT_NEAR(q.min_dihedral_rad, kPi / 4, 1e-12);
  EXPECT_NEAR(q.max_dihedral_rad, kPi / 2, 1e-12);
  EXPECT_EQ(q.sliver_count, 0u);
  EXPECT_GT(q.min_radius_ratio, 0.5);
  EXPECT_EQ(q.unreferenced_node_count, 0u);
}

TEST(TetMesh, SliverIsAcceptedAndCounted) {
  // Four points nearly on a circle in the z = 0 plane, lifted by 1e-3: a classic sliver.
  std::vector<Eigen::Vector3d> x = {{1, 0, 0}, {0, 1, 1e-3}, {-1, 0, 0}, {0, -1, 1e-3}};
  std::vector<Tet> tets = {{0, 1, 2, 3}};
  if (signed_volume(x[0], x[1], x[2], x[3]) < 0) {
    std::swap(tets[0][2], tets[0][3]);
  }
  const TetMesh mesh(x, tets);
  EXPECT_EQ(mesh.quality().sliver_count, 1u);
  EXPECT_EQ(mesh.quality().poor_radius_ratio_count, 1u);
}

TEST(TetMesh, RejectsInvertedFlatAndOutOfRange) {
  const std::vector<Eigen::Vector3d> x = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}};
  EXPECT_THROW(TetMesh(x, {{0, 2, 1, 3}}), std::invalid_argument);  // inverted
  EXPECT_THROW(TetMesh(x, {{0, 1, 4, 2}}), std::invalid_argument);  // flat
  EXPECT_THROW(TetMesh(x, {{0, 1, 2, 7}}), std::invalid_argument);  // out of range
  EXPECT_NO_THROW(TetMesh(x, {{0, 1, 2, 3}}));
}

TEST(SurfaceMesh, SphereIsClosedManifoldWithOutwardNormals) {
  const SurfaceMesh sphere = test::icosphere(2, 1.0);
  EXPECT_TRUE(sphere.is_closed());
  EXPECT_TRUE(sphere.is_manifold());
  for (std::size_t v = 0; v < sphere.vertex_count(); ++v) {
    EXPECT_GT(sphere.vertex_normals()[v].dot(sphere.vertices()[v]), 0.99);
  }
  EXPECT_GT(sphere.enclosed_volume_m3(), 0.0);
}

TEST(SurfaceMesh, DetectsHolesFlipsAndPinchedVertices) {
  SurfaceMesh sphere = test::icosphere(1, 1.0);
  std::vector<Triangle> open(sphere.triangles().begin() + 1, sphere.triangles().end());
  const SurfaceMesh holed(sphere.vertices(), open);
  EXPECT_FALSE(holed.is_closed());
  EXPECT_EQ(holed.topology().boundary_edge_count, 3u);

  std::vector<Triangle> flipped = sphere.triangles();
  std::swap(flipped[0][1], flipped[0][2]);
  EXPECT_FALSE(SurfaceMesh(sphere.vertices(), flipped).is_manifold());

  // Two tetrahedron surfaces sharing one vertex: closed, edge-manifold, but pinched.
  const std::vector<Eigen::Vector3d> x = {{0, 0, 0},  {1, 0, 0},  {0, 1, 0}, {0, 0, 1},
                                          {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
  const std::vector<Triangle> t = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1},
                                   {4, 6, 5}, {0, 5, 6}, {0, 4, 5}, {0, 6, 4}};
  const SurfaceMesh pinched(x, t);
  EXPECT_TRUE(pinched.is_closed());
  EXPECT_EQ(pinched.topology().non_manifold_vertex_count, 1u);
  EXPECT_FALSE(pinched.is_manifold());
}

}  // namespace
}  // namespace fahr::geometry
