// The neonatal scene (see scene.h).
#include "scene.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

#include "fahr/geometry/surface_loader.h"
#include "fahr/geometry/tetgen_loader.h"

namespace fahr::aist_bench {
namespace {

constexpr double kMillimetre = 1e-3;

std::vector<std::uint32_t> read_fixed_nodes(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  std::vector<std::uint32_t> nodes;
  std::string line;
  while (std::getline(in, line)) {
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    long value = 0;
    while (words >> value) nodes.push_back(static_cast<std::uint32_t>(value));
  }
  return nodes;
}

geometry::SignedDistanceField make_field(const geometry::SurfaceMesh& surface, double cell) {
  geometry::SdfOptions options;
  options.cell_size_m = cell;
  return geometry::SignedDistanceField(surface, options);
}

}  // namespace

std::unique_ptr<Scene> load_scene(double blade_cell_m, const std::string& dir) {
  auto tongue = geometry::load_tetgen(dir + "/tongue", kMillimetre);
  std::vector<geometry::Index> s2n;
  auto boundary = tongue.boundary_surface(&s2n);
  auto boundary_sdf = make_field(boundary, 1e-3);
  auto blade = geometry::load_surface(dir + "/miller1.obj", kMillimetre);
  auto blade_sdf = make_field(blade, blade_cell_m);
  auto scene = std::make_unique<Scene>(Scene{std::move(tongue),
                                             read_fixed_nodes(dir + "/tongue_fixed_nodes.txt"),
                                             std::move(boundary),
                                             std::move(s2n),
                                             std::move(boundary_sdf),
                                             std::move(blade),
                                             std::move(blade_sdf),
                                             0.0,
                                             {},
                                             0.0});
  double sum = 0.0;
  for (const auto& t : scene->boundary.triangles()) {
    for (int k = 0; k < 3; ++k)
      sum += (scene->boundary.vertices()[t[k]] - scene->boundary.vertices()[t[(k + 1) % 3]]).norm();
  }
  scene->mean_boundary_edge_m = sum / (3.0 * static_cast<double>(scene->boundary.triangle_count()));
  // Dorsum profile: boundary vertices within 5 mm of the mid-line (the blade is ~10 mm wide).
  constexpr double kHalfWidth = 5e-3;
  const auto& v = scene->boundary.vertices();
  double x0 = 1e9, x1 = -1e9;
  for (const auto& p : v) {
    x0 = std::min(x0, p.x());
    x1 = std::max(x1, p.x());
  }
  scene->dorsum_x0_m = x0;
  scene->dorsum_y_m.assign(static_cast<std::size_t>((x1 - x0) / kMillimetre) + 1,
                           -std::numeric_limits<double>::infinity());
  for (const auto& p : v) {
    if (std::abs(p.z()) > kHalfWidth) continue;
    auto& y = scene->dorsum_y_m[static_cast<std::size_t>((p.x() - x0) / kMillimetre)];
    y = std::max(y, p.y());
  }
  return scene;
}

namespace {

double smoothstep(double u) {
  u = std::clamp(u, 0.0, 1.0);
  return u * u * (3.0 - 2.0 * u);
}

// The lowest tip height that keeps a straight underside at this pitch above
// the rest dorsum (plus a clearance) along the first 40 mm of the blade.
double clear_tip_height(const Scene& scene, double tip_x, double pitch) {
  constexpr double kClearance = 0.2e-3;
  constexpr double kBladeReach = 40e-3;
  double y = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < scene.dorsum_y_m.size(); ++i) {
    const double x = scene.dorsum_x0_m + (static_cast<double>(i) + 0.5) * kMillimetre;
    if (x < tip_x - kMillimetre || x > tip_x + kBladeReach) continue;
    y = std::max(y, scene.dorsum_y_m[i] - std::max(0.0, x - tip_x) * std::tan(pitch) + kClearance);
  }
  return std::isfinite(y) ? y : 0.5 * kMillimetre;
}

}  // namespace

Eigen::Isometry3d blade_pose(const Scene& scene, double s, double lever_depth_m) {
  const double degree = std::numbers::pi / 180.0;
  const double x_start = 12 * kMillimetre, x_end = -33 * kMillimetre;
  const double w_slide = smoothstep(s / 0.5);
  const double tip_x = x_start + w_slide * (x_end - x_start);
  double pitch = 8.0 * degree * w_slide;
  double tip_y = std::max(0.5 * kMillimetre - w_slide, clear_tip_height(scene, tip_x, pitch));
  if (s > 0.5)
    tip_y =
        clear_tip_height(scene, x_end, 8.0 * degree) - lever_depth_m * smoothstep((s - 0.5) / 0.3);
  if (s > 0.8) {
    const double w = smoothstep((s - 0.8) / 0.2);
    pitch += 4.0 * degree * w;
    tip_y -= 1.0 * kMillimetre * w;
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  pose.translation() = Eigen::Vector3d(tip_x, tip_y, 0.0);
  return pose;
}

std::unique_ptr<fem::Body> make_tongue_body(const Scene& scene) {
  fem::BodySettings settings;
  settings.gravity_m_per_s2 = Eigen::Vector3d(-9.81, 0, 0);
  settings.time_step = std::chrono::duration<double>(0.002);
  settings.solver.refactor_period = 0;
  std::vector<Eigen::Vector3d> x = scene.tongue.rest_positions();
  std::vector<fem::Tet> tets;
  for (const auto& t : scene.tongue.tets()) {
    tets.push_back({static_cast<std::uint32_t>(t[0]), static_cast<std::uint32_t>(t[1]),
                    static_cast<std::uint32_t>(t[2]), static_cast<std::uint32_t>(t[3])});
  }
  fem::BodyOrError made = fem::Body::create(settings, x, tets, scene.fixed_nodes);
  if (!made.error.empty()) throw std::runtime_error("FEM body: " + made.error);
  return std::move(made.body);
}

}  // namespace fahr::aist_bench
