// geometry_bench: for each mesh, SDF build time, query time (exact band and
// far field, ns/query) and max error against the brute-force closest point
// over all triangles (signed by the winding number). Meshes: the ArtiSynth tongue boundary and jaw
// (../shared/meshes/artisynth-tongue beside the checkout; the bench fails without them) and
// meshes/neonatal/*.obj.
//
// usage: geometry_bench [--cell-mm C] [--neonatal-unit U] [--queries N] [--markdown [FILE]]
//                       [extra.obj ...]
//   C: grid cell (mm, default 1); U: unit of the neonatal OBJ files in metres
//   (default 0.001, millimetres); extra files are read in millimetres.
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "fahr/bench_support/results_file.h"
#include "fahr/geometry/load_error.h"
#include "fahr/geometry/signed_distance_field.h"
#include "fahr/geometry/surface_loader.h"
#include "fahr/geometry/tetgen_loader.h"

namespace {

using fahr::geometry::SdfOptions;
using fahr::geometry::SignedDistanceField;
using fahr::geometry::SurfaceMesh;
using Clock = std::chrono::steady_clock;

constexpr std::uint32_t kSeed = 1234;
constexpr int kErrorSamples = 2000;  // brute force costs O(triangles) each

struct Input {
  std::string name;
  SurfaceMesh mesh;
};

struct Row {
  std::string name;
  std::size_t triangles = 0;
  bool signed_field = true;
  double build_ms = 0.0;
  std::string grid;
  double band_ns = 0.0;
  double far_ns = 0.0;
  double exact_ns = 0.0;
  double band_error_mm = 0.0;
  double far_error_mm = 0.0;
};

// Points within the band: surface points pushed along a random direction by up to the band.
std::vector<Eigen::Vector3d> band_points(const SurfaceMesh& mesh, double band_m, int count,
                                         std::mt19937& rng) {
  std::uniform_int_distribution<std::size_t> pick(0, mesh.triangle_count() - 1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const auto& t = mesh.triangles()[pick(rng)];
    double a = u(rng);
    double b = u(rng);
    if (a + b > 1.0) {
      a = 1.0 - a;
      b = 1.0 - b;
    }
    const Eigen::Vector3d on = mesh.vertices()[t[0]] +
                               a * (mesh.vertices()[t[1]] - mesh.vertices()[t[0]]) +
                               b * (mesh.vertices()[t[2]] - mesh.vertices()[t[0]]);
    points.push_back(on + band_m * u(rng) * Eigen::Vector3d(g(rng), g(rng), g(rng)).normalized());
  }
  return points;
}

// Points in the grid's box whose grid value lies outside the exact band.
std::vector<Eigen::Vector3d> far_points(const SignedDistanceField& sdf, int count,
                                        std::mt19937& rng) {
  const Eigen::Vector3d lo = sdf.grid_origin_m();
  const Eigen::Vector3d span =
      sdf.cell_size_m() * (sdf.grid_dimensions() - Eigen::Vector3i::Ones()).cast<double>();
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<std::size_t>(count));
  for (int attempts = 0; static_cast<int>(points.size()) < count && attempts < 100 * count;
       ++attempts) {
    const Eigen::Vector3d p = lo + span.cwiseProduct(Eigen::Vector3d(u(rng), u(rng), u(rng)));
    if (!sdf.query(p).exact) {
      points.push_back(p);
    }
  }
  return points;
}

template <typename Query>
double ns_per_query(const std::vector<Eigen::Vector3d>& points, Query query) {
  if (points.empty()) {
    return 0.0;
  }
  double sink = 0.0;
  constexpr int kRepeats = 5;  // several passes so the clock's resolution does not matter
  const auto start = Clock::now();
  for (int r = 0; r < kRepeats; ++r) {
    for (const auto& p : points) {
      sink += query(p).distance_m;
    }
  }
  const double ns = std::chrono::duration<double, std::nano>(Clock::now() - start).count();
  if (!std::isfinite(sink)) {
    std::fprintf(stderr, "non-finite distance\n");
  }
  return ns / (kRepeats * static_cast<double>(points.size()));
}

// Generalised winding number (solid angles, Van Oosterom and Strackee 1983):
// about 1 inside a closed outward surface, 0 outside; an inside test that does
// not share the SDF's pseudo-normals.
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

// Max |query - reference| (mm): reference = brute-force distance, signed by
// the winding number when the field is signed, so sign errors count too.
double max_error_mm(const SurfaceMesh& mesh, const SignedDistanceField& sdf,
                    const std::vector<Eigen::Vector3d>& points) {
  double worst = 0.0;
  const std::size_t n = std::min<std::size_t>(points.size(), kErrorSamples);
  for (std::size_t i = 0; i < n; ++i) {
    double reference = std::sqrt(sdf.bvh().closest_point_brute_force(points[i]).distance_squared);
    if (sdf.is_signed() && winding_number(mesh, points[i]) > 0.5) {
      reference = -reference;
    }
    worst = std::max(worst, std::abs(sdf.query(points[i]).distance_m - reference));
  }
  return worst * 1e3;
}

Row measure(const Input& input, double cell_m, int queries) {
  Row row;
  row.name = input.name;
  row.triangles = input.mesh.triangle_count();
  row.signed_field =
      input.mesh.is_closed() && input.mesh.is_manifold() && !input.mesh.topology().folded();
  SdfOptions options;
  options.cell_size_m = cell_m;
  options.unsigned_mode = !row.signed_field;
  const auto start = Clock::now();
  const SignedDistanceField sdf(input.mesh, options);
  row.build_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  const Eigen::Vector3i d = sdf.grid_dimensions();
  row.grid = std::to_string(d.x()) + "x" + std::to_string(d.y()) + "x" + std::to_string(d.z());
  std::mt19937 rng(kSeed);
  const auto band = band_points(input.mesh, sdf.band_m(), queries, rng);
  const auto far = far_points(sdf, queries, rng);
  row.band_ns = ns_per_query(band, [&](const Eigen::Vector3d& p) { return sdf.query(p); });
  row.far_ns = ns_per_query(far, [&](const Eigen::Vector3d& p) { return sdf.query(p); });
  row.exact_ns = ns_per_query(far, [&](const Eigen::Vector3d& p) { return sdf.query_exact(p); });
  row.band_error_mm = max_error_mm(input.mesh, sdf, band);
  row.far_error_mm = max_error_mm(input.mesh, sdf, far);
  return row;
}

void load_into(std::vector<Input>& inputs, const std::string& label,
               const std::filesystem::path& path, double unit_m) {
  try {
    inputs.push_back(
        {label + path.filename().string(), fahr::geometry::load_surface(path, unit_m)});
  } catch (const fahr::geometry::LoadError& e) {
    std::fprintf(stderr, "skipped: %s\n", e.what());
  }
}

}  // namespace

int main(int argc, char** argv) {
  fahr::bench_support::MarkdownResults results(argc, argv);
  double cell_mm = 1.0;
  double neonatal_unit_m = 0.001;
  int queries = 20000;
  std::vector<std::filesystem::path> extra;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--cell-mm" && i + 1 < argc) {
      cell_mm = std::atof(argv[++i]);
    } else if (arg == "--neonatal-unit" && i + 1 < argc) {
      neonatal_unit_m = std::atof(argv[++i]);
    } else if (arg == "--queries" && i + 1 < argc) {
      queries = std::atoi(argv[++i]);
    } else if (!arg.empty() && arg[0] == '-') {
      std::fprintf(stderr,
                   "usage: %s [--cell-mm C] [--neonatal-unit U] [--queries N] [--markdown [FILE]] "
                   "[extra.obj ...]\n",
                   argv[0]);
      return 2;
    } else {
      extra.emplace_back(arg);
    }
  }
  if (!(cell_mm > 0.0) || queries <= 0) {
    std::fprintf(stderr, "--cell-mm and --queries must be positive\n");
    return 2;
  }
  results.begin("geometry");

  std::vector<Input> inputs;
  const std::filesystem::path artisynth = FAHR_ARTISYNTH_DIR;
  for (const char* name : {"tongue.1.node", "jaw.obj"}) {
    if (!std::filesystem::exists(artisynth / name)) {
      std::fprintf(stderr,
                   "geometry_bench: ArtiSynth mesh not found at %s "
                   "(../shared/meshes/artisynth-tongue must be beside the checkout)\n",
                   (artisynth / name).c_str());
      return 1;
    }
  }
  inputs.push_back({"artisynth tongue (boundary)",
                    fahr::geometry::load_tetgen(artisynth / "tongue.1", 1.0).boundary_surface()});
  load_into(inputs, "artisynth ", artisynth / "jaw.obj", 0.001);
  const std::filesystem::path neonatal = FAHR_NEONATAL_DIR;
  std::vector<std::filesystem::path> neonatal_files;
  if (std::filesystem::is_directory(neonatal)) {
    for (const auto& entry : std::filesystem::directory_iterator(neonatal)) {
      if (entry.path().extension() == ".obj") {
        neonatal_files.push_back(entry.path());
      }
    }
  }
  std::sort(neonatal_files.begin(), neonatal_files.end());
  if (neonatal_files.empty()) {
    std::printf("no meshes/neonatal/*.obj yet: skipped\n");
  }
  for (const auto& file : neonatal_files) {
    load_into(inputs, "neonatal/", file, neonatal_unit_m);
  }
  for (const auto& file : extra) {
    load_into(inputs, "", file, 0.001);
  }

  std::vector<std::string> notes;
  std::printf(
      "\nSDF benchmark: cell %.3g mm, band 3 cells, %d queries per set, max error over %d samples "
      "vs brute force\n\n",
      cell_mm, queries, kErrorSamples);
  std::printf(
      "| mesh | triangles | mode | grid | build ms | band ns/q | far ns/q | exact-only ns/q | band "
      "max err mm | far max err mm |\n");
  std::printf("| --- | ---: | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |\n");
  for (const Input& input : inputs) {
    const auto& t = input.mesh.topology();
    if (!input.mesh.is_closed() || !input.mesh.is_manifold() || t.folded()) {
      notes.push_back(input.name + ": unsigned, because of " +
                      std::to_string(t.boundary_edge_count) + " boundary, " +
                      std::to_string(t.non_manifold_edge_count) + " non-manifold, " +
                      std::to_string(t.inconsistent_edge_count) + " inconsistent, " +
                      std::to_string(t.folded_edge_count) + " folded edges and " +
                      std::to_string(t.non_manifold_vertex_count) + " non-manifold vertices");
    }
    const Row r = measure(input, cell_mm * 1e-3, queries);
    std::printf("| %s | %zu | %s | %s | %.0f | %.0f | %.0f | %.0f | %.2g | %.3f |\n",
                r.name.c_str(), r.triangles, r.signed_field ? "signed" : "unsigned", r.grid.c_str(),
                r.build_ms, r.band_ns, r.far_ns, r.exact_ns, r.band_error_mm, r.far_error_mm);
  }
  for (const std::string& note : notes) {
    std::printf("\n%s", note.c_str());
  }
  std::printf("\n");
  return 0;
}
