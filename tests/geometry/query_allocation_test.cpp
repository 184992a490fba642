// Proves the SDF and BVH queries allocate nothing (they run in the 1 kHz
// haptic tick), counted with fahr::test::AllocationCounter.
#include <gtest/gtest.h>

#include <random>

#include "allocation_counter.h"
#include "fahr/geometry/signed_distance_field.h"
#include "test_support.h"

namespace fahr::geometry {
namespace {

TEST(QueryAllocation, SdfQueriesAllocateNothing) {
  const SurfaceMesh sphere = test::icosphere(3, 0.01);
  SdfOptions options;
  options.cell_size_m = 0.001;
  const SignedDistanceField sdf(sphere, options);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  std::vector<Eigen::Vector3d> points(1000);
  for (auto& p : points) {
    p = Eigen::Vector3d(u(rng), u(rng), u(rng));
  }
  double sink = 0.0;
  fahr::test::AllocationCounter counter;
  for (const auto& p : points) {
    sink += sdf.query(p).distance_m + sdf.query_exact(p).distance_m + sdf.grid_distance(p);
    sink += sdf.bvh().closest_point(p, 1e-4).distance_squared;
  }
  EXPECT_EQ(counter.count(), 0) << "queries allocated";
  EXPECT_TRUE(std::isfinite(sink));
}

}  // namespace
}  // namespace fahr::geometry
