// Signed distance field grids kept on disk: a second build reads the grid and
// answers bit for bit as a built one; a damaged, stale or foreign file is
// rebuilt and replaced; an unwritable directory only costs the caching.
#include "sdf_cache.h"  // private to fahr::geometry: the white-box cases

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "fahr/geometry/signed_distance_field.h"
#include "test_support.h"

namespace fahr::geometry {
namespace {

namespace fs = std::filesystem;

class SdfCache : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("fahr-sdf-cache-test-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  SdfOptions options(const fs::path& dir) const {
    SdfOptions o;
    o.cell_size_m = 0.002;
    o.cache_dir = dir;
    return o;
  }

  std::vector<fs::path> grid_files() const {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir_)) files.push_back(e.path());
    return files;
  }

  fs::path dir_;
  SurfaceMesh surface_ = test::icosphere(2, 0.02, Eigen::Vector3d(0.001, -0.002, 0.003));
};

// Grid values, far-field and band answers of two fields at the same points.
void expect_identical(const SignedDistanceField& a, const SignedDistanceField& b) {
  std::mt19937 rng(20261129);
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  for (int s = 0; s < 2000; ++s) {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    ASSERT_EQ(a.grid_distance(p), b.grid_distance(p)) << "at " << p.transpose();
    ASSERT_EQ(a.query(p).distance_m, b.query(p).distance_m) << "at " << p.transpose();
  }
}

TEST_F(SdfCache, ASecondBuildReadsTheGridAndAnswersBitForBit) {
  const SignedDistanceField uncached(surface_, options({}));
  EXPECT_EQ(uncached.grid_source(), SdfGridSource::kBuilt);

  const SignedDistanceField first(surface_, options(dir_));
  EXPECT_EQ(first.grid_source(), SdfGridSource::kBuiltAndCached) << first.cache_note();
  EXPECT_TRUE(first.cache_note().empty()) << first.cache_note();
  ASSERT_EQ(grid_files().size(), 1u);

  const SignedDistanceField second(surface_, options(dir_));
  EXPECT_EQ(second.grid_source(), SdfGridSource::kCacheHit) << second.cache_note();
  expect_identical(uncached, second);

  // Another cell, another surface: other grids, not the cached one.
  SdfOptions finer = options(dir_);
  finer.cell_size_m = 0.0015;
  EXPECT_EQ(SignedDistanceField(surface_, finer).grid_source(), SdfGridSource::kBuiltAndCached);
  const SurfaceMesh moved = test::icosphere(2, 0.02, Eigen::Vector3d(0.001, -0.002, 0.0031));
  EXPECT_EQ(SignedDistanceField(moved, options(dir_)).grid_source(),
            SdfGridSource::kBuiltAndCached);
  EXPECT_EQ(grid_files().size(), 3u);
}

TEST_F(SdfCache, ADamagedFileIsRebuiltAndReplaced) {
  const SignedDistanceField reference(surface_, options(dir_));
  ASSERT_EQ(grid_files().size(), 1u);
  const fs::path file = grid_files().front();
  {
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(fs::file_size(file) / 2));
    f.put('\x5a');
  }
  const SignedDistanceField rebuilt(surface_, options(dir_));
  EXPECT_EQ(rebuilt.grid_source(), SdfGridSource::kBuiltAndCached);
  EXPECT_NE(rebuilt.cache_note().find("checksum"), std::string::npos) << rebuilt.cache_note();
  expect_identical(reference, rebuilt);
  EXPECT_EQ(SignedDistanceField(surface_, options(dir_)).grid_source(), SdfGridSource::kCacheHit);

  // Cut short: refused as truncated, rebuilt.
  fs::resize_file(file, fs::file_size(file) - 100);
  const SignedDistanceField again(surface_, options(dir_));
  EXPECT_NE(again.cache_note().find("truncated"), std::string::npos) << again.cache_note();
  expect_identical(reference, again);
}

// A file under the right key with a valid checksum but other values (grid
// code changed without its version bumped): the recomputed nodes disagree.
TEST_F(SdfCache, AStaleGridWithAValidChecksumIsCaughtByRecomputedNodes) {
  const SignedDistanceField reference(surface_, options(dir_));
  const fs::path file = grid_files().front();
  const std::string name = file.filename().string();
  const std::uint64_t key = std::stoull(name.substr(4, 16), nullptr, 16);
  const Eigen::Vector3i dims = reference.grid_dimensions();
  std::vector<double> stale(static_cast<std::size_t>(dims.prod()), 0.0);
  for (std::size_t i = 0; i < stale.size(); ++i) stale[i] = 1e-3 * static_cast<double>(i % 7);
  std::string why;
  ASSERT_TRUE(detail::write_sdf_grid(dir_, key, stale, why)) << why;

  const SignedDistanceField rebuilt(surface_, options(dir_));
  EXPECT_EQ(rebuilt.grid_source(), SdfGridSource::kBuiltAndCached);
  EXPECT_NE(rebuilt.cache_note().find("differ"), std::string::npos) << rebuilt.cache_note();
  expect_identical(reference, rebuilt);
}

TEST_F(SdfCache, AnUnwritableDirectoryOnlyCostsTheCaching) {
  // A regular file where the directory should be: nothing can be created under it.
  { std::ofstream(dir_) << "not a directory"; }
  const SignedDistanceField field(surface_, options(dir_ / "fields"));
  EXPECT_EQ(field.grid_source(), SdfGridSource::kBuilt);
  EXPECT_NE(field.cache_note().find(dir_.string()), std::string::npos) << field.cache_note();
  expect_identical(SignedDistanceField(surface_, options({})), field);
}

}  // namespace
}  // namespace fahr::geometry
