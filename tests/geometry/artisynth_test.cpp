// The real ArtiSynth tongue (TetGen, metres) and jaw (OBJ, millimetres):
// external input the loaders must read. Without ../shared/meshes/artisynth-tongue
// beside the checkout these tests fail, naming the path.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include "fahr/geometry/signed_distance_field.h"
#include "fahr/geometry/surface_loader.h"
#include "fahr/geometry/tetgen_loader.h"

namespace fahr::geometry {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

std::filesystem::path artisynth_dir() {
  return FAHR_ARTISYNTH_DIR;
}

// Generalised winding number (solid angle sum over triangles, Van Oosterom and
// Strackee 1983): about 1 inside a closed outward surface, 0 outside. An
// inside test independent of the pseudo-normals the SDF uses.
double winding_number(const SurfaceMesh& mesh, const Eigen::Vector3d& p) {
  double solid_angle = 0.0;
  for (const auto& t : mesh.triangles()) {
    const Eigen::Vector3d a = mesh.vertices()[t[0]] - p;
    const Eigen::Vector3d b = mesh.vertices()[t[1]] - p;
    const Eigen::Vector3d c = mesh.vertices()[t[2]] - p;
    const double la = a.norm();
    const double lb = b.norm();
    const double lc = c.norm();
    solid_angle += 2.0 * std::atan2(a.dot(b.cross(c)),
                                    la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return solid_angle / (4.0 * 3.14159265358979323846);
}

TEST(ArtiSynth, TongueLoadsWithQualityStatistics) {
  const auto stem = artisynth_dir() / "tongue.1";
  ASSERT_TRUE(std::filesystem::exists(stem.string() + ".node"))
      << "ArtiSynth tongue not found at " << stem.string()
      << ".node: ../shared/meshes/artisynth-tongue must be beside the checkout";
  const TetMesh mesh = load_tetgen(stem, 1.0);
  const TetQualityStats& q = mesh.quality();
  std::printf(
      "[ tongue ] %zu nodes, %zu tets, %zu boundary faces\n"
      "[ tongue ] volume total %.3f cm^3; per tet min %.4g, mean %.4g, max %.4g mm^3\n"
      "[ tongue ] dihedral min %.2f deg, max %.2f deg; radius ratio min %.4f, mean %.4f\n"
      "[ tongue ] slivers (dihedral outside [%.0f, %.0f] deg): %zu; radius ratio < %.2f: %zu; "
      "unreferenced nodes: %zu\n",
      mesh.node_count(), mesh.tet_count(), mesh.boundary_faces().size(), q.total_volume_m3 * 1e6,
      q.min_volume_m3 * 1e9, q.mean_volume_m3 * 1e9, q.max_volume_m3 * 1e9,
      q.min_dihedral_rad * kRadToDeg, q.max_dihedral_rad * kRadToDeg, q.min_radius_ratio,
      q.mean_radius_ratio, kSliverMinDihedralDeg, kSliverMaxDihedralDeg, q.sliver_count,
      kPoorRadiusRatio, q.poor_radius_ratio_count, q.unreferenced_node_count);
  EXPECT_EQ(mesh.node_count(), 2228u);
  EXPECT_EQ(mesh.tet_count(), 11098u);
  EXPECT_EQ(mesh.boundary_faces().size(), 1812u);  // what TetGen wrote in tongue.1.face
  const SurfaceMesh surface = mesh.boundary_surface();
  EXPECT_TRUE(surface.is_closed());
  EXPECT_TRUE(surface.is_manifold());
  // The outward boundary encloses exactly the tets' volume.
  EXPECT_NEAR(surface.enclosed_volume_m3(), q.total_volume_m3, 1e-9 * q.total_volume_m3);
}

TEST(ArtiSynth, TongueSurfaceSdf) {
  const auto stem = artisynth_dir() / "tongue.1";
  ASSERT_TRUE(std::filesystem::exists(stem.string() + ".node"))
      << "ArtiSynth tongue not found at " << stem.string()
      << ".node: ../shared/meshes/artisynth-tongue must be beside the checkout";
  const SurfaceMesh surface = load_tetgen(stem, 1.0).boundary_surface();
  SdfOptions options;
  options.cell_size_m = 0.001;
  const auto start = std::chrono::steady_clock::now();
  const SignedDistanceField sdf(surface, options);
  const double build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::mt19937 rng(7);
  const Eigen::Vector3d lo = surface.bounds_min().array() - 0.005;
  const Eigen::Vector3d hi = surface.bounds_max().array() + 0.005;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double max_exact = 0.0;
  double max_far = 0.0;
  for (int s = 0; s < 2000; ++s) {
    const Eigen::Vector3d p = lo + (hi - lo).cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    const SdfSample q = sdf.query(p);
    const double reference = std::sqrt(sdf.bvh().closest_point_brute_force(p).distance_squared);
    const double error = std::abs(std::abs(q.distance_m) - reference);
    (q.exact ? max_exact : max_far) = std::max(q.exact ? max_exact : max_far, error);
    // Signs agree with the winding number (0.5: halfway between outside and inside).
    if (std::abs(q.distance_m) > 1e-9) {
      EXPECT_EQ(q.distance_m<0.0, winding_number(surface, p)> 0.5) << "at " << p.transpose();
    }
  }
  std::printf(
      "[ tongue ] SDF cell 1 mm: build %.0f ms, grid %dx%dx%d; |d| max error exact %.3g mm, far "
      "%.4f mm\n",
      build_ms, sdf.grid_dimensions().x(), sdf.grid_dimensions().y(), sdf.grid_dimensions().z(),
      max_exact * 1e3, max_far * 1e3);
  EXPECT_LT(max_exact, 1e-12);
  EXPECT_LT(max_far, std::sqrt(3.0) * options.cell_size_m);
  // A node of the tet mesh deep inside is inside.
  EXPECT_LT(sdf.query(0.5 * (surface.bounds_min() + surface.bounds_max())).distance_m, 0.0);
}

TEST(ArtiSynth, JawObjLoads) {
  const auto jaw = artisynth_dir() / "jaw.obj";
  ASSERT_TRUE(std::filesystem::exists(jaw))
      << "ArtiSynth jaw not found at " << jaw.string()
      << ": ../shared/meshes/artisynth-tongue must be beside the checkout";
  const SurfaceMesh mesh = load_surface(jaw, 0.001);
  const SurfaceTopology& t = mesh.topology();
  std::printf(
      "[ jaw ] %zu vertices, %zu triangles; boundary edges %zu, non-manifold edges %zu, "
      "inconsistent edges %zu, non-manifold vertices %zu, degenerate triangles %zu\n",
      mesh.vertex_count(), mesh.triangle_count(), t.boundary_edge_count, t.non_manifold_edge_count,
      t.inconsistent_edge_count, t.non_manifold_vertex_count, t.degenerate_triangle_count);
  EXPECT_EQ(mesh.triangle_count(), 3844u);
  EXPECT_LT((mesh.bounds_max() - mesh.bounds_min()).maxCoeff(), 0.5);  // millimetres became metres
}

}  // namespace
}  // namespace fahr::geometry
