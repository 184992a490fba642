// SignedDistanceField grids on disk: see sdf_cache.h.
#include "sdf_cache.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <system_error>

namespace fahr::geometry::detail {
namespace {

constexpr std::array<char, 8> kMagic = {'F', 'A', 'H', 'R', 'S', 'D', 'F', '\0'};

// FNV-1a, 64 bit (Fowler, Noll, Vo): order-sensitive and cheap; a key, not a
// cryptographic digest (the cache directory is the user's own).
class Fnv1a {
 public:
  void bytes(const void* data, std::size_t size) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) {
      state_ ^= p[i];
      state_ *= 1099511628211ULL;
    }
  }
  template <typename T>
  void value(const T& v) {
    bytes(&v, sizeof(T));
  }
  std::uint64_t digest() const { return state_; }

 private:
  std::uint64_t state_ = 14695981039346656037ULL;
};

struct Header {
  std::array<char, 8> magic = kMagic;
  std::uint32_t version = kSdfGridVersion;
  std::uint32_t value_bytes = sizeof(double);
  std::uint64_t key = 0;
  std::uint64_t count = 0;
  std::uint64_t values_checksum = 0;
};

std::uint64_t checksum(const std::vector<double>& values) {
  Fnv1a h;
  h.bytes(values.data(), values.size() * sizeof(double));
  return h.digest();
}

// The directory is kept under this size: after a write, the grids read or
// written longest ago go first (a read touches its file), and temporary
// files older than an hour (a writer killed mid-write) too.
constexpr std::uintmax_t kCacheBudgetBytes = std::uintmax_t{1} << 30;

void trim(const std::filesystem::path& dir) {
  std::error_code ec;
  struct Entry {
    std::filesystem::file_time_type time;
    std::uintmax_t size;
    std::filesystem::path path;
  };
  std::vector<Entry> grids;
  std::uintmax_t total = 0;
  const auto now = std::filesystem::file_time_type::clock::now();
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("sdf-", 0) != 0) continue;
    const auto time = entry.last_write_time(ec);
    if (ec) continue;
    if (name.find(".tmp") != std::string::npos) {
      if (now - time > std::chrono::hours(1)) std::filesystem::remove(entry.path(), ec);
      continue;
    }
    const std::uintmax_t size = entry.file_size(ec);
    if (ec) continue;
    grids.push_back({time, size, entry.path()});
    total += size;
  }
  std::sort(grids.begin(), grids.end(),
            [](const Entry& a, const Entry& b) { return a.time < b.time; });
  for (const Entry& grid : grids) {
    if (total <= kCacheBudgetBytes) break;
    if (std::filesystem::remove(grid.path, ec)) total -= grid.size;
  }
}

}  // namespace

std::uint64_t sdf_grid_key(const SdfGridIdentity& identity) {
  Fnv1a h;
  h.value(kSdfGridVersion);
  h.value(static_cast<std::uint64_t>(identity.vertices.size()));
  for (const Eigen::Vector3d& v : identity.vertices) {
    h.value(v.x());
    h.value(v.y());
    h.value(v.z());
  }
  h.value(static_cast<std::uint64_t>(identity.triangles.size()));
  for (const Triangle& t : identity.triangles) h.value(t);
  h.value(identity.cell_size_m);
  h.value(identity.band_m);
  h.value(identity.signed_field);
  for (int axis = 0; axis < 3; ++axis) {
    h.value(identity.origin[axis]);
    h.value(identity.dims[axis]);
  }
  return h.digest();
}

std::filesystem::path sdf_cache_file(const std::filesystem::path& dir, std::uint64_t key) {
  char name[40];
  std::snprintf(name, sizeof(name), "sdf-%016llx.grid", static_cast<unsigned long long>(key));
  return dir / name;
}

bool read_sdf_grid(const std::filesystem::path& dir, std::uint64_t key, std::size_t expected_count,
                   std::vector<double>& values, std::string& why) {
  why.clear();
  const std::filesystem::path file = sdf_cache_file(dir, key);
  std::ifstream in(file, std::ios::binary);
  if (!in) return false;  // not cached yet
  Header header;
  in.read(reinterpret_cast<char*>(&header), sizeof(header));
  if (!in || header.magic != kMagic || header.value_bytes != sizeof(double)) {
    why = file.string() + ": not a fahr field grid";
    return false;
  }
  if (header.version != kSdfGridVersion || header.key != key) {
    why = file.string() + ": written by another version (grid version " +
          std::to_string(header.version) + ")";
    return false;
  }
  if (header.count != expected_count) {
    why = file.string() + ": holds " + std::to_string(header.count) + " nodes, the grid has " +
          std::to_string(expected_count);
    return false;
  }
  values.resize(expected_count);
  in.read(reinterpret_cast<char*>(values.data()),
          static_cast<std::streamsize>(expected_count * sizeof(double)));
  if (!in || in.gcount() != static_cast<std::streamsize>(expected_count * sizeof(double))) {
    why = file.string() + ": truncated";
    return false;
  }
  if (checksum(values) != header.values_checksum) {
    why = file.string() + ": checksum mismatch (the file is damaged)";
    return false;
  }
  std::error_code ec;  // recently used: the last to be trimmed
  std::filesystem::last_write_time(file, std::filesystem::file_time_type::clock::now(), ec);
  return true;
}

bool write_sdf_grid(const std::filesystem::path& dir, std::uint64_t key,
                    const std::vector<double>& values, std::string& why) {
  why.clear();
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    why = dir.string() + ": " + ec.message();
    return false;
  }
  const std::filesystem::path file = sdf_cache_file(dir, key);
  // One temporary name per writer (process and call): two services, or two
  // threads, building the same field at once each write their own and the
  // last rename wins, with equal contents.
  static std::atomic<unsigned> writes{0};
  std::filesystem::path temporary = file;
  temporary += ".tmp" + std::to_string(::getpid()) + "-" + std::to_string(writes.fetch_add(1));
  Header header;
  header.key = key;
  header.count = values.size();
  header.values_checksum = checksum(values);
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(&header), sizeof(header));
    out.write(reinterpret_cast<const char*>(values.data()),
              static_cast<std::streamsize>(values.size() * sizeof(double)));
    out.flush();
    if (!out) {
      why = temporary.string() + ": cannot write";
      out.close();
      std::filesystem::remove(temporary, ec);
      return false;
    }
  }
  std::filesystem::rename(temporary, file, ec);
  if (ec) {
    why = file.string() + ": " + ec.message();
    std::filesystem::remove(temporary, ec);
    return false;
  }
  trim(dir);
  return true;
}

}  // namespace fahr::geometry::detail
