// Signed distance field against analytic shapes and brute-force closest points.
#include "fahr/geometry/signed_distance_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "test_support.h"

namespace fahr::geometry {
namespace {

// Exact answers come from the same closest-point code as the brute force, so
// they agree to rounding: 1e-12 m is a thousand times the double rounding of
// centimetre coordinates and a million times below any haptic resolution.
constexpr double kExactToleranceM = 1e-12;
constexpr std::uint32_t kSeed = 20261122;

// Signed distance to a convex closed mesh by testing every triangle: inside
// when p lies behind every face plane.
double brute_force_convex(const SurfaceMesh& mesh, const SignedDistanceField& sdf,
                          const Eigen::Vector3d& p) {
  const double d = std::sqrt(sdf.bvh().closest_point_brute_force(p).distance_squared);
  for (std::size_t f = 0; f < mesh.triangle_count(); ++f) {
    if (mesh.face_normals()[f].dot(p - mesh.vertices()[mesh.triangles()[f][0]]) > 0.0) {
      return d;
    }
  }
  return -d;
}

struct ErrorReport {
  double max_exact_error_m = 0.0;
  double max_far_error_m = 0.0;
  int exact_count = 0;
  int far_count = 0;
};

ErrorReport compare(const SurfaceMesh& mesh, const SignedDistanceField& sdf,
                    const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, int samples) {
  std::mt19937 rng(kSeed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  ErrorReport report;
  for (int s = 0; s < samples; ++s) {
    const Eigen::Vector3d p = lo + (hi - lo).cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    const double reference = brute_force_convex(mesh, sdf, p);
    const SdfSample q = sdf.query(p);
    const double error = std::abs(q.distance_m - reference);
    if (q.exact) {
      ++report.exact_count;
      report.max_exact_error_m = std::max(report.max_exact_error_m, error);
      EXPECT_NEAR((q.closest_point_m - p).norm(), std::abs(reference), kExactToleranceM);
      EXPECT_NEAR(q.normal.norm(), 1.0, 1e-12);
    } else {
      ++report.far_count;
      report.max_far_error_m = std::max(report.max_far_error_m, error);
      // Points truly within the band are always answered exactly.
      EXPECT_GT(std::abs(reference), sdf.band_m())
          << "far answer inside the band at " << p.transpose();
    }
  }
  return report;
}

void print(const char* name, const SignedDistanceField& sdf, const ErrorReport& r) {
  std::printf(
      "[ sdf ] %s: cell %.2f mm, band %.2f mm, grid %dx%dx%d; %d exact (max error %.3g mm), "
      "%d far (max error %.4f mm)\n",
      name, sdf.cell_size_m() * 1e3, sdf.band_m() * 1e3, sdf.grid_dimensions().x(),
      sdf.grid_dimensions().y(), sdf.grid_dimensions().z(), r.exact_count,
      r.max_exact_error_m * 1e3, r.far_count, r.max_far_error_m * 1e3);
}

TEST(SignedDistanceField, SphereMatchesBruteForce) {
  const double radius = 0.01;
  const SurfaceMesh sphere = test::icosphere(3, radius);
  SdfOptions options;
  options.cell_size_m = 0.001;
  options.margin_m = 0.005;
  const SignedDistanceField sdf(sphere, options);
  const Eigen::Vector3d half = Eigen::Vector3d::Constant(0.02);
  const ErrorReport r = compare(sphere, sdf, -half, half, 3000);
  print("icosphere r 10 mm, 1280 triangles", sdf, r);
  EXPECT_LT(r.max_exact_error_m, kExactToleranceM);
  EXPECT_LT(r.max_far_error_m, std::sqrt(3.0) * options.cell_size_m);
  EXPECT_GT(r.exact_count, 100);
  EXPECT_GT(r.far_count, 100);
  // Against the analytic sphere: the polyhedron lies within its sagitta of it.
  const double sagitta = radius - std::abs(sdf.query_exact(Eigen::Vector3d::Zero()).distance_m);
  EXPECT_NEAR(sdf.query(Eigen::Vector3d(0.0, 0.0, 0.015)).distance_m, 0.005, sagitta + 1e-12);
  EXPECT_LT(sdf.query(Eigen::Vector3d::Zero()).distance_m, -0.009);
}

TEST(SignedDistanceField, BoxMatchesAnalytic) {
  const Eigen::Vector3d half(0.015, 0.01, 0.005);
  const SurfaceMesh box = test::box_surface(half, 2);
  SdfOptions options;
  options.cell_size_m = 0.0005;
  const SignedDistanceField sdf(box, options);
  std::mt19937 rng(kSeed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double max_exact = 0.0;
  double max_far = 0.0;
  for (int s = 0; s < 3000; ++s) {
    const Eigen::Vector3d p = 1.5 * half.cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    const Eigen::Vector3d q = p.cwiseAbs() - half;
    const double analytic = q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
    const SdfSample sample = sdf.query(p);
    (sample.exact ? max_exact : max_far) =
        std::max(sample.exact ? max_exact : max_far, std::abs(sample.distance_m - analytic));
    if (sample.exact && q.maxCoeff() > 0.0 && (q.array() > 0.0).count() == 1) {
      // Outside, facing one face: the normal is that face's axis.
      int axis = 0;
      q.maxCoeff(&axis);
      EXPECT_NEAR(std::abs(sample.normal[axis]), 1.0, 1e-9);
    }
  }
  std::printf(
      "[ sdf ] box 30x20x10 mm, cell 0.5 mm: max exact error %.3g mm, max far error %.4f mm\n",
      max_exact * 1e3, max_far * 1e3);
  EXPECT_LT(max_exact, kExactToleranceM);
  EXPECT_LT(max_far, std::sqrt(3.0) * options.cell_size_m);
}

TEST(SignedDistanceField, OpenMeshIsRefusedUnlessUnsigned) {
  const SurfaceMesh sphere = test::icosphere(2, 0.01);
  const std::vector<Triangle> open(sphere.triangles().begin() + 1, sphere.triangles().end());
  const SurfaceMesh holed(sphere.vertices(), open);
  SdfOptions options;
  options.cell_size_m = 0.002;
  try {
    SignedDistanceField refused(holed, options);
    ADD_FAILURE() << "an open mesh must be refused";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("not a closed manifold"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("unsigned_mode"), std::string::npos) << e.what();
  }
  options.unsigned_mode = true;
  const SignedDistanceField sdf(holed, options);
  EXPECT_FALSE(sdf.is_signed());
  std::mt19937 rng(kSeed);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  for (int s = 0; s < 500; ++s) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    const SdfSample q = sdf.query(p);
    EXPECT_GE(q.distance_m, 0.0);
    if (q.exact) {
      EXPECT_NEAR(q.distance_m, std::sqrt(sdf.bvh().closest_point_brute_force(p).distance_squared),
                  kExactToleranceM);
    }
  }
}

TEST(SignedDistanceField, PinchedMeshIsRefused) {
  const std::vector<Eigen::Vector3d> x = {{0, 0, 0},  {1, 0, 0},  {0, 1, 0}, {0, 0, 1},
                                          {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
  const std::vector<Triangle> t = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1},
                                   {4, 6, 5}, {0, 5, 6}, {0, 4, 5}, {0, 6, 4}};
  SdfOptions options;
  options.cell_size_m = 0.1;
  EXPECT_THROW(SignedDistanceField(SurfaceMesh(x, t), options), std::invalid_argument);
}

TEST(SignedDistanceField, TetMeshBoundary) {
  const TetMesh cube = test::cube_tets(4, 0.005);  // 20 mm cube from 0 to 20 mm
  SdfOptions options;
  options.cell_size_m = 0.001;
  const SignedDistanceField sdf(cube.boundary_surface(), options);
  EXPECT_NEAR(sdf.query(Eigen::Vector3d(0.01, 0.01, 0.003)).distance_m, -0.003, kExactToleranceM);
  EXPECT_NEAR(sdf.query(Eigen::Vector3d(0.01, 0.01, 0.01)).distance_m, -0.01,
              std::sqrt(3.0) * options.cell_size_m);
  EXPECT_NEAR(sdf.query(Eigen::Vector3d(0.01, 0.01, 0.022)).distance_m, 0.002, kExactToleranceM);
  EXPECT_TRUE(sdf.query(Eigen::Vector3d(0.01, 0.01, 0.022))
                  .normal.isApprox(Eigen::Vector3d::UnitZ(), 1e-12));
}

}  // namespace
}  // namespace fahr::geometry

namespace fahr::geometry {
namespace {

TEST(SignedDistanceField, FoldedMeshIsRefusedUnlessUnsigned) {
  // A zero-thickness sheet: two triangles back to back. Closed and manifold by
  // its indices, but it has no inside.
  const SurfaceMesh sheet({{0, 0, 0}, {0.01, 0, 0}, {0, 0.01, 0}}, {{0, 1, 2}, {0, 2, 1}});
  EXPECT_TRUE(sheet.is_closed());
  EXPECT_TRUE(sheet.is_manifold());
  EXPECT_EQ(sheet.topology().folded_edge_count, 3u);
  SdfOptions options;
  options.cell_size_m = 0.001;
  EXPECT_THROW(SignedDistanceField(sheet, options), std::invalid_argument);
  options.unsigned_mode = true;
  const SignedDistanceField sdf(sheet, options);
  EXPECT_NEAR(sdf.query(Eigen::Vector3d(0.002, 0.002, 0.002)).distance_m, 0.002, kExactToleranceM);
}

TEST(SignedDistanceField, NonFiniteQueryGivesNaN) {
  SdfOptions options;
  options.cell_size_m = 0.002;
  const SignedDistanceField sdf(test::icosphere(1, 0.01), options);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_TRUE(std::isnan(sdf.query(Eigen::Vector3d(nan, 0.0, 0.0)).distance_m));
  EXPECT_TRUE(std::isnan(sdf.query_exact(Eigen::Vector3d(0.0, nan, 0.0)).distance_m));
  EXPECT_TRUE(std::isnan(sdf.grid_distance(Eigen::Vector3d(0.0, 0.0, nan))));
  // Far outside the grid the answer stays finite and positive.
  EXPECT_GT(sdf.query(Eigen::Vector3d(1e3, 0.0, 0.0)).distance_m, 999.0);
}

}  // namespace
}  // namespace fahr::geometry
