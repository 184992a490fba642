// The epiglottis's leaf as a cantilever: how stiff two linear tets through
// a 1.2 mm thickness bend, against finer meshes of the same strip and the
// plate-strip formula. The generated leaf (meshes/neonatal/epiglottis.*) is
// a 13 x 11 x 2 lattice of Kuhn-split cells over 9.5 mm x 9.3 mm x 1.2 mm,
// curled; this strip is the same lattice flat, so the ratio of its tip
// deflection to a converged mesh's is what the leaf's discretisation adds
// to its bending stiffness (the curl stiffens it further, for any mesh).
#include <cmath>
#include <cstdio>
#include <vector>

#include "bench_util.h"
#include "fahr/fem/box_mesh.h"

namespace fahr::fem::bench {
namespace {

constexpr double kLength_m = 9.5e-3;
constexpr double kWidth_m = 9.3e-3;
constexpr double kThickness_m = 1.2e-3;
constexpr double kYoungs_pa = 1e6;  // bench/support/soft_epiglottis_scene.sh's estimate
constexpr double kPoisson = 0.45;
// A tip deflection of L / 1000: linear.
constexpr double kTargetDeflection_m = kLength_m * 1e-3;

// The plate strip clamped along one edge, a line load at the other:
// D = E t^3 / (12 (1 - nu^2)) per unit width.
double plate_stiffness_per_width() {
  return kYoungs_pa * std::pow(kThickness_m, 3) / (12.0 * (1.0 - kPoisson * kPoisson));
}
double tip_load_n() {
  return 3.0 * plate_stiffness_per_width() * kWidth_m * kTargetDeflection_m /
         std::pow(kLength_m, 3);
}

// One implicit step of h = 1000 s from rest without damping: K u = f.
double static_deflection(const std::array<int, 3>& cells, std::size_t& tets) {
  const BodyMesh mesh = make_box_mesh(cells, Eigen::Vector3d(kLength_m, kThickness_m, kWidth_m));
  tets = mesh.tets.size();
  std::vector<std::uint32_t> fixed;
  std::vector<std::uint32_t> tip;
  for (std::size_t i = 0; i < mesh.nodes_m.size(); ++i) {
    if (mesh.nodes_m[i].x() < 1e-12) fixed.push_back(static_cast<std::uint32_t>(i));
    if (mesh.nodes_m[i].x() > kLength_m - 1e-12) tip.push_back(static_cast<std::uint32_t>(i));
  }
  BodySettings settings;
  settings.material.youngs_modulus_pa = kYoungs_pa;
  settings.material.poisson_ratio = kPoisson;
  settings.material.density_kg_per_m3 = 1100.0;
  settings.material.rayleigh_mass_per_s = 0.0;
  settings.material.rayleigh_stiffness_s = 0.0;
  settings.gravity_m_per_s2.setZero();
  settings.time_step = std::chrono::duration<double>(1000.0);
  settings.sleep.enabled = false;
  BodyOrError made = Body::create(settings, mesh.nodes_m, mesh.tets, fixed);
  if (!made.error.empty()) {
    std::fprintf(stderr, "leaf: %s\n", made.error.c_str());
    return NAN;
  }
  const Eigen::Vector3d per_node(0.0, -tip_load_n() / static_cast<double>(tip.size()), 0.0);
  for (const std::uint32_t node : tip) made.body->set_external_force(node, per_node);
  made.body->step();
  double sum = 0.0;
  for (const std::uint32_t node : tip)
    sum += made.body->rest_position(node).y() - made.body->position(node).y();
  return sum / static_cast<double>(tip.size());
}

}  // namespace

void run_leaf() {
  std::printf(
      "\n## The epiglottis's leaf as a flat cantilever: %.1f x %.1f x %.1f mm, E %g Pa, nu "
      "%.2f, tip load %.3g N\n\n",
      1e3 * kLength_m, 1e3 * kWidth_m, 1e3 * kThickness_m, kYoungs_pa, kPoisson, tip_load_n());
  std::printf(
      "Plate strip: tip deflection P L^3 / (3 D b) = %.6f mm. Cells along the length x "
      "across x through the thickness, six Kuhn tets a cell; the first row is the generated "
      "leaf's lattice.\n\n",
      1e3 * kTargetDeflection_m);
  std::printf(
      "| cells | tets | tip deflection mm | / plate strip | stiffer than the finest by x |\n");
  std::printf("| --- | ---: | ---: | ---: | ---: |\n");
  const std::vector<std::array<int, 3>> meshes = {
      {13, 2, 11}, {13, 4, 11}, {13, 8, 11}, {26, 4, 22}, {52, 8, 44}};
  std::vector<double> deflections;
  std::vector<std::size_t> tets;
  double finest = 0.0;  // the last mesh's
  for (const auto& cells : meshes) {
    std::size_t n = 0;
    finest = static_deflection(cells, n);
    deflections.push_back(finest);
    tets.push_back(n);
  }
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    std::printf("| %d x %d x %d | %zu | %.6f | %.3f | %.2f |\n", meshes[i][0], meshes[i][2],
                meshes[i][1], tets[i], 1e3 * deflections[i], deflections[i] / kTargetDeflection_m,
                finest / deflections[i]);
  }
}

}  // namespace fahr::fem::bench
