// The shipped neonatal tongue with the floor of the mouth (meshes/neonatal,
// 7,758 tets, fixed where the floor meets the mandible and the hyoid, as the
// scene fixes it) under a blade's load: 7.9 N (the Touch X's peak
// force) pushing down (-y, towards the floor of the mouth) on the dorsal
// surface under a 10 x 40 mm patch along the mid-line, as a uniform
// pressure, for 5 s, then released; the scene's material, gravity (-x,
// supine) and 200 Hz step. Stable Neo-Hookean against corotational (what
// each inverts, how it recovers), and what a step costs by part on this
// tongue. The requirement and what is met are stated at each test.
#include <gtest/gtest.h>
#include <time.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fahr/fem/cholmod_solver.h"
#include "fahr/fem/contact_step.h"
#include "fahr/geometry/signed_distance_field.h"
#include "fahr/geometry/surface_loader.h"
#include "fahr/geometry/tet_deformation.h"
#include "scenes.h"
#include "tetgen.h"

namespace fahr::fem {
namespace {

struct NeonatalTongue {
  BodyMesh mesh;
  std::vector<std::uint32_t> fixed;
  std::vector<std::array<std::uint32_t, 3>> faces;
};

bool load_neonatal_tongue(NeonatalTongue& tongue, std::string& error) {
  const std::string stem = std::string(FAHR_NEONATAL_DIR) + "/tongue";
  if (!test::read_tetgen(stem, tongue.mesh, error)) return false;
  for (Eigen::Vector3d& p : tongue.mesh.nodes_m) p *= 1e-3;  // the files are in mm
  tongue.faces = test::read_tetgen_faces(stem, 0, error);
  if (tongue.faces.empty()) return false;
  std::ifstream fixed(std::string(FAHR_NEONATAL_DIR) + "/tongue_fixed_nodes.txt");
  std::string line;
  while (std::getline(fixed, line)) {
    if (line.empty() || line[0] == '#') continue;
    tongue.fixed.push_back(static_cast<std::uint32_t>(std::stoul(line)));
  }
  if (tongue.fixed.empty()) {
    error = "no fixed nodes read";
    return false;
  }
  return true;
}

// A rigid part of the scene's anatomy (an OBJ of meshes/neonatal, mm) as
// the FEM's obstacle, through its signed distance field (0.5 mm cells, the
// scene's default), as the FEM service adapts it.
class AnatomyObstacle final : public ObstacleField {
 public:
  explicit AnatomyObstacle(const std::string& obj) {
    surface_ = geometry::load_surface(std::string(FAHR_NEONATAL_DIR) + "/" + obj, 1e-3);
    geometry::SdfOptions options;
    options.cell_size_m = 0.5e-3;
    sdf_ = std::make_unique<geometry::SignedDistanceField>(surface_, options);
    far_error_m_ = std::sqrt(3.0) * options.cell_size_m;
  }
  ObstacleSample sample(const Eigen::Vector3d& p_m) const noexcept override {
    ObstacleSample out;
    const geometry::SdfSample s = sdf_->query(p_m);
    // Far outside the band the field may overestimate by a cell diagonal.
    out.distance_m = !s.exact && s.distance_m > 0.0 ? s.distance_m - far_error_m_ : s.distance_m;
    out.normal = s.normal;
    return out;
  }

 private:
  geometry::SurfaceMesh surface_;
  std::unique_ptr<geometry::SignedDistanceField> sdf_;
  double far_error_m_ = 0.0;
};

// The material of deployment/scenes/neonatal_intubation.yaml's tongue.
Material scene_tongue(MaterialModel model) {
  Material m;
  m.youngs_modulus_pa = 10000.0;
  m.poisson_ratio = 0.45;
  m.density_kg_per_m3 = 1040.0;
  m.rayleigh_mass_per_s = 0.1;
  m.rayleigh_stiffness_s = 0.01;
  m.yeoh_c20_over_c10 = model == MaterialModel::kStableNeoHookean ? kTongueYeohC20OverC10 : 0.0;
  m.model = model;
  return m;
}

// Per node, the force of a uniform pressure on the dorsal triangles under
// the blade: triangles facing up (outward normal y > 0.5) with their
// centroid within 5 mm of the mid-line and within 40 mm of the dorsum's
// front; each gives a third of its area to each corner. Returns the patch
// area, m^2, and fills `load` (N per unit pressure, -y).
double blade_patch(const NeonatalTongue& tongue, std::vector<Eigen::Vector3d>& load,
                   std::size_t& nodes) {
  const auto& x = tongue.mesh.nodes_m;
  auto normal = [&](const std::array<std::uint32_t, 3>& f) {
    return Eigen::Vector3d((x[f[1]] - x[f[0]]).cross(x[f[2]] - x[f[0]]));
  };
  auto centroid = [&](const std::array<std::uint32_t, 3>& f) {
    return Eigen::Vector3d((x[f[0]] + x[f[1]] + x[f[2]]) / 3.0);
  };
  double front = -1e9;
  for (const auto& f : tongue.faces) {
    if (normal(f).normalized().y() > 0.5) front = std::max(front, centroid(f).x());
  }
  load.assign(x.size(), Eigen::Vector3d::Zero());
  double area = 0.0;
  for (const auto& f : tongue.faces) {
    const Eigen::Vector3d n = normal(f);
    const Eigen::Vector3d c = centroid(f);
    if (n.normalized().y() > 0.5 && std::abs(c.z()) <= 0.005 && c.x() >= front - 0.040) {
      const double a = 0.5 * n.norm();
      area += a;
      for (const std::uint32_t node : f) load[node] += Eigen::Vector3d(0.0, -a / 3.0, 0.0);
    }
  }
  nodes = static_cast<std::size_t>(std::count_if(
      load.begin(), load.end(), [](const Eigen::Vector3d& v) { return v.y() < 0.0; }));
  return area;
}

int inverted_tets(const Body& body) {
  const ElementRest& rest = body.element_rest();
  int inverted = 0;
  for (std::size_t e = 0; e < rest.size(); ++e) {
    const Eigen::Matrix3d f =
        geometry::deformation_gradient(body.positions_m().data(), rest.tets[e], rest.dm_inv[e]);
    inverted += f.determinant() > 0.0 ? 0 : 1;
  }
  return inverted;
}

double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const auto i = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(i), v.end());
  return v[i];
}

struct PressResult {
  int tets = 0;                   // of the loaded mesh
  int most_inverted_hold = 0;     // most tets inverted after any step of the hold
  int most_inverted_release = 0;  // ... of the 100 ms after release
  int inverted_end = 0;           // 1 s after release
  double deepest_m = 0.0;         // largest node displacement from the settled state
  double back_m = 0.0;            // largest distance from the settled state, 1 s after
  bool finite = true;
  std::uint64_t factorisations = 0;
  std::vector<double> step_ms, refactor_step_ms, other_step_ms;
};

constexpr double kBladeForceN = 7.9;

// Loads the blade's pressure over `ramp_steps` steps (1: at once), holds it
// for 5 s in all, removes it and steps 1 s more. on_anatomy: the tongue and
// its floor also meet the scene's mandible, hyoid and palate, kept out of
// them by the FEM's own anatomy projection (ContactStep with obstacles, the
// scene's anatomy settings, no volume floor); otherwise only its fixed
// nodes hold it.
PressResult press_and_release(MaterialModel model, bool on_anatomy, int ramp_steps) {
  PressResult result;
  NeonatalTongue tongue;
  std::string error;
  EXPECT_TRUE(load_neonatal_tongue(tongue, error)) << error;
  EXPECT_GE(tongue.mesh.tets.size(), 5603u);  // at least the tongue alone had before the floor
  result.tets = static_cast<int>(tongue.mesh.tets.size());
  BodySettings settings;
  settings.material = scene_tongue(model);
  settings.time_step = std::chrono::milliseconds(5);  // the scene's 200 Hz
  settings.gravity_m_per_s2 = Eigen::Vector3d(-9.81, 0.0, 0.0);
  settings.solver.refactor_period = 0;  // the FEM service's lagged factorisation
  settings.sleep.enabled = false;
  auto body = test::make_body(settings, tongue.mesh, tongue.fixed);
  EXPECT_NE(body, nullptr);
  if (!body) return result;
  const SphereLinks no_spheres;
  ContactStep contact_step(*body, no_spheres);
  std::vector<std::unique_ptr<AnatomyObstacle>> anatomy;
  std::vector<const ObstacleField*> fields;
  if (on_anatomy) {
    for (const char* part : {"jaw.obj", "hyoid.obj", "palate.obj"}) {
      anatomy.push_back(std::make_unique<AnatomyObstacle>(part));
      fields.push_back(anatomy.back().get());
    }
    contact_step.set_obstacles(fields);
  }
  // The blade's load, N per DOF: forces of each step (ContactStep owns the
  // body's external forces, so both paths take them this way).
  std::vector<double> blade_n(3 * body->node_count(), 0.0);
  auto step = [&] {
    if (on_anatomy) return contact_step.step(nullptr, blade_n);
    for (std::uint32_t i = 0; i < body->node_count(); ++i)
      body->set_external_force(i, Eigen::Map<const Eigen::Vector3d>(&blade_n[3 * std::size_t{i}]));
    return body->step();
  };
  std::vector<Eigen::Vector3d> load;
  std::size_t patch_nodes = 0;
  const double area = blade_patch(tongue, load, patch_nodes);
  const double pressure = kBladeForceN / area;
  std::printf("[ info ] blade patch %.0f mm^2 over %zu surface nodes, %.0f Pa\n", 1e6 * area,
              patch_nodes, pressure);
  // Settle under gravity for 0.5 s: "rest" is where the tongue lies then.
  for (int k = 0; k < 100; ++k) step();
  std::vector<Eigen::Vector3d> settled;
  for (std::uint32_t i = 0; i < body->node_count(); ++i) settled.push_back(body->position(i));
  auto farthest = [&] {
    double d = 0.0;
    for (std::uint32_t i = 0; i < body->node_count(); ++i)
      d = std::max(d, (body->position(i) - settled[i]).norm());
    return d;
  };
  const std::uint64_t factorisations_before = body->factorisations();
  auto timed_step = [&] {
    const double start = thread_cpu_ms();
    const StepReport report = step();
    const double ms = thread_cpu_ms() - start;
    result.step_ms.push_back(ms);
    (report.refactorised ? result.refactor_step_ms : result.other_step_ms).push_back(ms);
    result.finite = result.finite && !report.solve_failed && test::all_finite(*body);
  };
  for (int k = 0; k < 1000 && result.finite; ++k) {  // 5 s
    const double share = std::min(1.0, static_cast<double>(k + 1) / ramp_steps);
    for (std::uint32_t i = 0; i < body->node_count(); ++i) {
      for (Eigen::Index d = 0; d < 3; ++d)
        blade_n[3 * std::size_t{i} + static_cast<std::size_t>(d)] = share * pressure * load[i](d);
    }
    timed_step();
    result.most_inverted_hold = std::max(result.most_inverted_hold, inverted_tets(*body));
    result.deepest_m = std::max(result.deepest_m, farthest());
  }
  std::fill(blade_n.begin(), blade_n.end(), 0.0);
  for (int k = 0; k < 200 && result.finite; ++k) {  // 1 s
    timed_step();
    const int inverted = inverted_tets(*body);
    if (k < 20) result.most_inverted_release = std::max(result.most_inverted_release, inverted);
    result.inverted_end = inverted;
  }
  result.back_m = farthest();
  result.factorisations = body->factorisations() - factorisations_before;
  std::printf(
      "[ info ] %s tongue%s, %.1f N on the blade patch (reached in %d ms) for 5 s: deepest %.1f "
      "mm, most tets inverted %d (hold), %d (100 ms after release), %d (1 s after); 1 s after "
      "release %.3f mm from rest; %llu factorisations in 1,200 steps\n",
      model == MaterialModel::kStableNeoHookean ? "stable Neo-Hookean" : "corotational",
      on_anatomy ? " on the jaw" : ", base only", kBladeForceN, 5 * ramp_steps,
      1e3 * result.deepest_m, result.most_inverted_hold, result.most_inverted_release,
      result.inverted_end, 1e3 * result.back_m,
      static_cast<unsigned long long>(result.factorisations));
  std::printf(
      "[ info ] step CPU ms (thread; a shared machine): median %.2f p99 %.2f max %.2f; "
      "refactorising steps (%zu) median %.2f, the others median %.2f\n",
      percentile(result.step_ms, 0.5), percentile(result.step_ms, 0.99),
      percentile(result.step_ms, 1.0), result.refactor_step_ms.size(),
      percentile(result.refactor_step_ms, 0.5), percentile(result.other_step_ms, 0.5));
  return result;
}

// What a FEM step costs on the shipped tongue, by part, for both models, at
// a pressed state (40 steps of the blade's load): the elastic forces (every
// step), A's assembly with the tangent and the numeric factorisation (on a
// refresh), and the factorisation alone (CHOLMOD on a copy of A). Thread CPU,
// the best of several repetitions (the machine is shared). Prints; asserts
// nothing about time, so it is a measurement and not run with the suite:
// --gtest_also_run_disabled_tests --gtest_filter='*StepCostByPart*'.
TEST(HyperelasticTongue, DISABLED_StepCostByPart) {
  NeonatalTongue tongue;
  std::string error;
  ASSERT_TRUE(load_neonatal_tongue(tongue, error)) << error;
  std::printf(
      "| model | elastic forces ms | tangent + factorisation ms | factorisation alone ms | "
      "tangent (difference) ms |\n|---|---|---|---|---|\n");
  // Stable Neo-Hookean twice: every element's tangent computed again
  // (tangent_reuse_change 0), and the tangents kept where F did not move
  // (repeated refreshes at one state: the best case, only the assembly).
  for (const int variant : {0, 1, 2}) {
    const MaterialModel model =
        variant == 0 ? MaterialModel::kCorotational : MaterialModel::kStableNeoHookean;
    BodySettings settings;
    settings.material = scene_tongue(model);
    if (variant == 1) settings.solver.tangent_reuse_change = 0.0;
    settings.time_step = std::chrono::milliseconds(5);
    settings.gravity_m_per_s2 = Eigen::Vector3d(-9.81, 0.0, 0.0);
    settings.solver.refactor_period = 0;
    settings.sleep.enabled = false;
    auto body = test::make_body(settings, tongue.mesh, tongue.fixed);
    ASSERT_NE(body, nullptr);
    std::vector<Eigen::Vector3d> load;
    std::size_t nodes = 0;
    const double pressure = kBladeForceN / blade_patch(tongue, load, nodes);
    for (std::uint32_t i = 0; i < body->node_count(); ++i)
      if (load[i].y() < 0.0) body->set_external_force(i, pressure * load[i]);
    for (int k = 0; k < 40; ++k) body->step();
    std::vector<double> f(3 * body->node_count());
    auto best_ms = [](int repetitions, auto work) {
      double best = 1e300;
      for (int r = 0; r < repetitions; ++r) {
        const double start = thread_cpu_ms();
        work();
        best = std::min(best, thread_cpu_ms() - start);
      }
      return best;
    };
    const double forces = best_ms(20, [&] { body->elastic_forces(f); });
    const double refresh = best_ms(5, [&] { EXPECT_EQ(body->set_solver(settings.solver), ""); });
    SparseMatrix a = body->system_matrix();
    CholmodSolver cholmod;
    ASSERT_TRUE(cholmod.analyze(a, settings.solver.cholmod));
    const double factorisation = best_ms(5, [&] { EXPECT_TRUE(cholmod.factorize()); });
    const char* const names[] = {"corotational", "stable Neo-Hookean, every tangent",
                                 "stable Neo-Hookean, tangents kept"};
    std::printf("| %s | %.2f | %.2f | %.2f | %.2f |\n", names[variant], forces, refresh,
                factorisation, refresh - factorisation);
  }
}

// The load at once, the tongue held only where its floor meets bone ("base
// only": no contact with the bones themselves). Not met: "no tet inverted
// during the hold nor 100 ms after". Unsupported, the tongue and its floor
// sag like a hammock and are pushed some 60 mm down (62.5 mm with the floor
// of the mouth, 58 mm when the tongue was held at its whole base); the tets
// next to the fixed nodes are crushed through J = 0 (the bending stress
// there is several times lambda, and Stable Neo-Hookean has no barrier at
// J = 0, only a finite push back): 77 inverted at most, 59 100 ms after
// release (106 and 57 on the mesh before its light nodes were peeled). What is asserted: a small
// share inverted (the corotational tongue inverts about a quarter under the same load, the test
// below), none left 1 s after release, and the tongue back within 1 mm of rest.
TEST(HyperelasticTongue, BaseOnlyBladeLoadFor5sInvertsFewTetsAndTheTongueRecovers) {
  ASSERT_TRUE(std::filesystem::exists(std::string(FAHR_NEONATAL_DIR) + "/tongue.node"));
  const PressResult r = press_and_release(MaterialModel::kStableNeoHookean, false, 1);
  ASSERT_TRUE(r.finite);
  EXPECT_LT(r.most_inverted_hold, r.tets / 50);
  EXPECT_LT(r.most_inverted_release, r.tets / 50);
  EXPECT_EQ(r.inverted_end, 0);
  EXPECT_LT(r.back_m, 1e-3);
  EXPECT_GT(r.deepest_m, 1e-3);  // the load does press the tongue
}

// The same load on the corotational tongue, for the record: printed, with
// no expectation on inversion, so not run with the suite (a minute on a slow
// machine): --gtest_also_run_disabled_tests --gtest_filter='*CorotationalBaseOnly*'.
TEST(HyperelasticTongue, DISABLED_CorotationalBaseOnlyUnderTheSameLoad) {
  const PressResult r = press_and_release(MaterialModel::kCorotational, false, 1);
  EXPECT_TRUE(r.finite);
}

// On the jaw, the load reached in 0.5 s (a blade pressing), both models;
// printed only, and disabled (each takes over a minute): run with
// --gtest_also_run_disabled_tests --gtest_filter='*OnTheJaw*'. Without the
// scene's volume floor neither keeps the tongue out of the bone at 7.9 N:
// it is squeezed past the jaw and stays there after release.
TEST(HyperelasticTongue, DISABLED_OnTheJawUnderTheSameLoad) {
  for (const MaterialModel model : {MaterialModel::kStableNeoHookean, MaterialModel::kCorotational})
    press_and_release(model, true, 100);
}

}  // namespace
}  // namespace fahr::fem
