// Proves the SDF and BVH queries allocate nothing (they run in the 1 kHz
// haptic tick): global operator new is replaced by a counting one.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <random>

#include "fahr/geometry/signed_distance_field.h"
#include "test_support.h"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size)) {
    return p;
  }
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) {
  return operator new(size);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}

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
  const long before = g_allocations.load();
  for (const auto& p : points) {
    sink += sdf.query(p).distance_m + sdf.query_exact(p).distance_m + sdf.grid_distance(p);
    sink += sdf.bvh().closest_point(p, 1e-4).distance_squared;
  }
  const long after = g_allocations.load();
  EXPECT_EQ(after - before, 0) << "queries allocated";
  EXPECT_TRUE(std::isfinite(sink));
}

}  // namespace
}  // namespace fahr::geometry
