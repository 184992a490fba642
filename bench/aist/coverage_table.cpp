// Coverage and sphere counts on the neonatal and the ArtiSynth tongues.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "fahr/collision/sphere_state.h"
#include "fahr/geometry/tetgen_loader.h"
#include "fahr/sphere_layout/coverage.h"
#include "fahr/sphere_layout/fill_spheres.h"
#include "sections.h"
#include "stats.h"

namespace fahr::aist_bench {
namespace {

void row(const char* name, const geometry::TetMesh& mesh, const geometry::SurfaceMesh& boundary,
         const geometry::SignedDistanceField& sdf, const sphere_layout::FillSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  sphere_layout::SphereLayout layout;
  try {
    layout = sphere_layout::fill_spheres(mesh, settings);
  } catch (const std::invalid_argument& e) {
    std::printf("| %s | %.0f | %d | %s | refused: %s |\n", name, settings.volume_ratio,
                settings.refinement_levels, settings.surface_hugging ? "yes" : "no", e.what());
    return;
  }
  const double fill_ms = elapsed_us(start) / 1e3;
  const collision::SphereState rest(layout);
  sphere_layout::CoverageSettings coverage;
  coverage.sample_spacing_m = 0.2e-3;
  coverage.voxel_size_m = 0.2e-3;
  const auto report =
      sphere_layout::measure_coverage(rest.centres_m(), rest.radii_m(), boundary, sdf, coverage);
  std::printf(
      "| %s | %.0f | %d | %s | %zu | %zu / %zu / %zu | %zu | %.3f | %.3f | %.3f | %.3f | %.3f | "
      "%.0f |\n",
      name, settings.volume_ratio, settings.refinement_levels,
      settings.surface_hugging ? "yes" : "no", layout.size(), layout.count_at_level(0),
      layout.count_at_level(1), layout.count_at_level(2),
      layout.count(sphere_layout::SphereOrigin::kHugging), report.boundary_to_union_max_m * 1e3,
      report.boundary_to_union_p999_m * 1e3, report.boundary_to_union_mean_m * 1e3,
      report.union_to_boundary_max_m * 1e3, report.hausdorff_m() * 1e3, fill_ms);
  std::fflush(stdout);
}

// The rows of levels 0, 1 and 2, without and with surface-hugging spheres.
void every_level(const char* name, const geometry::TetMesh& mesh,
                 const geometry::SurfaceMesh& boundary, const geometry::SignedDistanceField& sdf) {
  for (const bool hugging : {false, true}) {
    for (const int levels : {0, 1, 2}) {
      sphere_layout::FillSettings s;
      s.refinement_levels = levels;
      s.surface_hugging = hugging;
      s.max_spheres = 60000;
      row(name, mesh, boundary, sdf, s);
    }
  }
}

}  // namespace

void coverage_table(const Scene& scene, const std::string& scene_dir) {
  // The ArtiSynth tongue is part of the table: without it the bench fails
  // before printing anything, naming the path.
  const std::filesystem::path artisynth = std::filesystem::path(FAHR_ARTISYNTH_DIR) / "tongue.1";
  if (!std::filesystem::exists(artisynth.string() + ".node")) {
    throw std::runtime_error("coverage: ArtiSynth tongue not found at " + artisynth.string() +
                             ".node (../shared/meshes/artisynth-tongue must be beside the "
                             "checkout)");
  }
  std::printf(
      "\n## Coverage (symmetric Hausdorff, boundary vs sphere-union outer surface, samples 0.2 "
      "mm)\n\n");
  std::printf(
      "| mesh | ratio | levels | hugging | spheres | level 0 / 1 / 2 | hugging | b->u max (mm) | "
      "b->u p99.9 (mm) | b->u mean (mm) | u->b max (mm) | Hausdorff (mm) | fill (ms) |\n");
  std::printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  every_level(("neonatal (" + std::to_string(scene.tongue.tet_count()) + " tets)").c_str(),
              scene.tongue, scene.boundary, scene.boundary_sdf);
  const geometry::TetMesh tongue = geometry::load_tetgen(artisynth, 1.0);
  const geometry::SurfaceMesh boundary = tongue.boundary_surface();
  geometry::SdfOptions options;
  options.cell_size_m = 1e-3;
  const geometry::SignedDistanceField sdf(boundary, options);
  for (const bool hugging : {false, true}) {
    sphere_layout::FillSettings s;
    s.surface_hugging = hugging;
    s.max_spheres = 60000;
    row("ArtiSynth (11,098 tets)", tongue, boundary, sdf, s);
  }
  // The epiglottis: a leaf 1.2 mm thick, its tets about 0.75 x 0.9 x 0.6 mm;
  // its field at 0.1 mm cells (a 1 mm cell is coarser than the leaf).
  const std::string leaf_path = scene_dir + "/epiglottis";
  if (!std::filesystem::exists(leaf_path + ".node")) return;
  const geometry::TetMesh leaf = geometry::load_tetgen(leaf_path, 1e-3);
  const geometry::SurfaceMesh leaf_boundary = leaf.boundary_surface();
  geometry::SdfOptions fine;
  fine.cell_size_m = 0.1e-3;
  const geometry::SignedDistanceField leaf_sdf(leaf_boundary, fine);
  every_level(("epiglottis leaf (" + std::to_string(leaf.tet_count()) + " tets)").c_str(), leaf,
              leaf_boundary, leaf_sdf);
}

}  // namespace fahr::aist_bench
