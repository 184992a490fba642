// The grid of a SignedDistanceField kept on disk, so a service that restarts
// (or a second service building the same field) reads it instead of
// recomputing it. One file per field, named by a 64-bit key over everything
// the grid's values depend on; written to a temporary file and renamed, so a
// reader never sees half a file. Private to fahr::geometry.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "fahr/geometry/mesh_types.h"

namespace fahr::geometry::detail {

// Bump when SignedDistanceField::fill_grid (or anything it calls) would give
// different node values for the same surface and options: cached grids of
// another version are ignored. The reader also recomputes a few nodes and
// compares, which catches a forgotten bump in most cases.
inline constexpr std::uint32_t kSdfGridVersion = 1;

// What identifies a grid: the surface exactly, the options that shape the
// grid, and the grid's placement derived from them.
struct SdfGridIdentity {
  std::span<const Eigen::Vector3d> vertices;
  std::span<const Triangle> triangles;
  double cell_size_m = 0.0;
  double band_m = 0.0;
  bool signed_field = true;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3i dims = Eigen::Vector3i::Zero();
};

std::uint64_t sdf_grid_key(const SdfGridIdentity& identity);

std::filesystem::path sdf_cache_file(const std::filesystem::path& dir, std::uint64_t key);

// Reads the grid stored under `key`; returns false (and says why in `why`,
// empty when there is simply no file) when it is absent, of another
// version or key, truncated, or its checksum does not match.
bool read_sdf_grid(const std::filesystem::path& dir, std::uint64_t key, std::size_t expected_count,
                   std::vector<double>& values, std::string& why);

// Writes the grid; returns false and says why when the directory or file
// cannot be written (the field is then simply not cached).
bool write_sdf_grid(const std::filesystem::path& dir, std::uint64_t key,
                    const std::vector<double>& values, std::string& why);

}  // namespace fahr::geometry::detail
