// fem_bullet_peer: fahr against Bullet 3.24's implicit deformable solver
// (btDeformableMultiBodyDynamicsWorld + btDeformableLinearElasticityForce),
// side by side in one run, on the ArtiSynth tongue: E 10 kPa, nu 0.45,
// h 10 ms, lowest 10 mm fixed, gravity. Usage: fem_bullet_peer [steps] [--markdown [FILE]]
//
// Bullet pitfalls handled (../shared/notes/dependency-facts.md): double
// precision build (bullet-float64) and a mesh centred on the origin; the
// soft-body world info gets gravity explicitly (and only there); tets are
// appended directly (no TetGen text parsing, no O(L^2) links); projection on.
#include <BulletCollision/BroadphaseCollision/btDbvtBroadphase.h>
#include <BulletSoftBody/btDeformableBodySolver.h>
#include <BulletSoftBody/btDeformableLinearElasticityForce.h>
#include <BulletSoftBody/btDeformableMultiBodyConstraintSolver.h>
#include <BulletSoftBody/btDeformableMultiBodyDynamicsWorld.h>
#include <BulletSoftBody/btSoftBodyRigidBodyCollisionConfiguration.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "bench_util.h"
#include "fahr/bench_support/results_file.h"
#include "fahr/fem/lumped_mass.h"
#include "tetgen_reader.h"

namespace fahr::fem::bench {
namespace {

constexpr double kStepS = 0.01;

Material peer_material() {
  Material m;
  m.youngs_modulus_pa = 10e3;
  m.poisson_ratio = 0.45;
  m.density_kg_per_m3 = 1040.0;
  m.rayleigh_mass_per_s = 1.0;
  m.rayleigh_stiffness_s = 0.01;
  return m;
}

double max_displacement(const std::vector<Eigen::Vector3d>& rest,
                        const std::vector<Eigen::Vector3d>& now) {
  double largest = 0.0;
  for (std::size_t i = 0; i < rest.size(); ++i)
    largest = std::max(largest, (now[i] - rest[i]).norm());
  return largest;
}

struct PeerResult {
  std::string name;
  double cpu_ms = 0.0;
  double sag_mm = 0.0;
  bool finite = true;
  std::string trace;  // max displacement, mm, every 25 steps
};

PeerResult run_fahr(const std::string& name, const BodyMesh& mesh,
                    const std::vector<std::uint32_t>& fixed, const SolverSettings& solver,
                    int steps) {
  BodySettings settings;
  settings.material = peer_material();
  settings.time_step = std::chrono::duration<double>(kStepS);
  settings.solver = solver;
  settings.sleep.enabled = false;
  BodyOrError made = Body::create(settings, mesh.nodes_m, mesh.tets, fixed);
  PeerResult result;
  result.name = name;
  if (!made.error.empty()) {
    std::fprintf(stderr, "fahr: %s\n", made.error.c_str());
    result.finite = false;
    return result;
  }
  const double start = thread_cpu_ms();
  for (int k = 0; k < steps; ++k) made.body->step();
  result.cpu_ms = (thread_cpu_ms() - start) / steps;
  std::vector<Eigen::Vector3d> now(mesh.nodes_m.size());
  for (std::uint32_t i = 0; i < now.size(); ++i) now[i] = made.body->position(i);
  for (const double x : made.body->positions_m()) result.finite = result.finite && std::isfinite(x);
  result.sag_mm = 1e3 * max_displacement(mesh.nodes_m, now);
  return result;
}

// Linear static reference: one undamped step of h = 1000 s from rest.
double linear_static_sag_mm(const BodyMesh& mesh, const std::vector<std::uint32_t>& fixed) {
  BodySettings settings;
  settings.material = peer_material();
  settings.material.rayleigh_mass_per_s = 0.0;
  settings.material.rayleigh_stiffness_s = 0.0;
  settings.time_step = std::chrono::duration<double>(1000.0);
  settings.sleep.enabled = false;
  BodyOrError made = Body::create(settings, mesh.nodes_m, mesh.tets, fixed);
  made.body->step();
  std::vector<Eigen::Vector3d> now(mesh.nodes_m.size());
  for (std::uint32_t i = 0; i < now.size(); ++i) now[i] = made.body->position(i);
  return 1e3 * max_displacement(mesh.nodes_m, now);
}

PeerResult run_bullet(const BodyMesh& mesh, const std::vector<std::uint32_t>& fixed, int steps) {
  PeerResult result;
  result.name = "Bullet 3.24 btDeformableMultiBodyDynamicsWorld + linear elasticity (float64)";
  const Material material = peer_material();
  const LameParameters lame = lame_parameters(material);
  btSoftBodyRigidBodyCollisionConfiguration config;
  btCollisionDispatcher dispatcher(&config);
  btDbvtBroadphase broadphase;
  btDeformableBodySolver solver;
  btDeformableMultiBodyConstraintSolver constraints;
  constraints.setDeformableSolver(&solver);
  btDeformableMultiBodyDynamicsWorld world(&dispatcher, &broadphase, &constraints, &config,
                                           &solver);
  const btVector3 gravity(0, -9.81, 0);
  world.setGravity(gravity);
  world.getWorldInfo().m_gravity = gravity;  // setGravity does not reach it
  world.setUseProjection(true);
  ElementRest rest;
  build_element_rest(mesh.nodes_m, mesh.tets, rest);
  const std::vector<double> mass =
      lumped_mass(rest, mesh.nodes_m.size(), material.density_kg_per_m3);
  std::vector<btVector3> x(mesh.nodes_m.size());
  std::vector<btScalar> m(mesh.nodes_m.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    x[i] = btVector3(mesh.nodes_m[i].x(), mesh.nodes_m[i].y(), mesh.nodes_m[i].z());
    m[i] = mass[i];
  }
  auto* body =
      new btSoftBody(&world.getWorldInfo(), static_cast<int>(x.size()), x.data(), m.data());
  for (const Tet& t : mesh.tets) {
    body->appendTetra(static_cast<int>(t[0]), static_cast<int>(t[1]), static_cast<int>(t[2]),
                      static_cast<int>(t[3]));
  }
  body->initializeDmInverse();
  body->m_tetraScratches.resize(body->m_tetras.size());
  body->m_tetraScratchesTn.resize(body->m_tetras.size());
  body->m_cfg.collisions = 0;
  body->m_sleepingThreshold = 0;
  for (const std::uint32_t node : fixed) body->setMass(static_cast<int>(node), 0);
  world.addSoftBody(body);
  btDeformableLinearElasticityForce elasticity(
      lame.mu_pa, lame.lambda_pa, material.rayleigh_mass_per_s, material.rayleigh_stiffness_s);
  world.addForce(body, &elasticity);
  // No btDeformableGravityForce: the world already applies the world-info
  // gravity to deformable nodes, and adding the force as well doubled the
  // sag (measured: 3.7 mm instead of 1.9 mm after 25 steps).
  // Bullet's solvers may print per step; keep the table readable.
  std::ostringstream sink;
  std::streambuf* saved = std::cout.rdbuf(sink.rdbuf());
  const double start = thread_cpu_ms();
  double cpu_in_steps = 0.0;
  for (int k = 0; k < steps; ++k) {
    const double before = thread_cpu_ms();
    world.stepSimulation(static_cast<btScalar>(kStepS), 0);
    cpu_in_steps += thread_cpu_ms() - before;
    if ((k + 1) % 25 == 0) {
      double largest = 0.0;
      for (std::size_t i = 0; i < x.size(); ++i)
        largest = std::max(largest, (body->m_nodes[static_cast<int>(i)].m_x - x[i]).length());
      double fixed_moved = 0.0;
      for (const std::uint32_t node : fixed) {
        fixed_moved =
            std::max(fixed_moved, (body->m_nodes[static_cast<int>(node)].m_x - x[node]).length());
      }
      char entry[64];
      std::snprintf(entry, sizeof(entry), " %.1f (fixed nodes %.2g)", 1e3 * largest,
                    1e3 * fixed_moved);
      result.trace += entry;
    }
  }
  (void)start;
  result.cpu_ms = cpu_in_steps / steps;
  std::cout.rdbuf(saved);
  std::vector<Eigen::Vector3d> now(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const btVector3& p = body->m_nodes[static_cast<int>(i)].m_x;
    now[i] = Eigen::Vector3d(p.x(), p.y(), p.z());
    result.finite = result.finite && now[i].allFinite();
  }
  result.sag_mm = 1e3 * max_displacement(mesh.nodes_m, now);
  world.removeSoftBody(body);
  delete body;
  return result;
}

}  // namespace
}  // namespace fahr::fem::bench

int main(int argc, char** argv) {
  using namespace fahr::fem;
  using namespace fahr::fem::bench;
  if (std::getenv("OMP_THREAD_LIMIT") == nullptr) {
    setenv("OMP_THREAD_LIMIT", "1", 1);  // see main.cpp of fem_bench
    setenv("OMP_WAIT_POLICY", "passive", 1);
    setenv("OPENBLAS_NUM_THREADS", "1", 1);
    execv("/proc/self/exe", argv);
  }
  fahr::bench_support::MarkdownResults markdown(argc, argv);
  markdown.begin("fem-bullet-peer");
  const int steps = argc > 1 ? std::atoi(argv[1]) : 150;
  const std::string stem = std::string(FAHR_TONGUE_DIR) + "/tongue.1";
  BodyMesh mesh;
  const std::string error = read_tetgen(stem, mesh);
  if (!error.empty()) {
    std::fprintf(stderr,
                 "fem_bullet_peer: cannot read the ArtiSynth tongue at %s (%s); "
                 "../shared/meshes/artisynth-tongue must be beside the checkout\n",
                 stem.c_str(), error.c_str());
    return 1;
  }
  // Centre on the origin (Bullet's pitfall) and fix the lowest 10 mm (+y up).
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : mesh.nodes_m) centre += p;
  centre /= static_cast<double>(mesh.nodes_m.size());
  double lowest = 1e9;
  for (auto& p : mesh.nodes_m) {
    p -= centre;
    lowest = std::min(lowest, p.y());
  }
  std::vector<std::uint32_t> fixed;
  for (std::size_t i = 0; i < mesh.nodes_m.size(); ++i) {
    if (mesh.nodes_m[i].y() < lowest + 0.010) fixed.push_back(static_cast<std::uint32_t>(i));
  }
  std::printf(
      "# fem_bullet_peer: ArtiSynth tongue, %zu tets, %zu nodes (%zu fixed), E 10 kPa, nu 0.45, "
      "h 10 ms, %d steps (%.2f s), gravity -y\n\n",
      mesh.tets.size(), mesh.nodes_m.size(), fixed.size(), steps, steps * kStepS);
  std::vector<PeerResult> results;
  // Converged fahr reference: exact step, run four times as long.
  const PeerResult reference = run_fahr("fahr reference (cholmod every step, 4x longer)", mesh,
                                        fixed, cholmod_exact().solver, 4 * steps);
  results.push_back(reference);
  results.push_back(
      run_fahr("fahr cholmod every step", mesh, fixed, cholmod_exact().solver, steps));
  SolverSettings lagged = cholmod_lagged(0).solver;
  results.push_back(
      run_fahr("fahr cholmod lagged, refactor on 0.1 rad rotation", mesh, fixed, lagged, steps));
  results.push_back(run_fahr("fahr cg lagged-chol rest factor tol 1e-6", mesh, fixed,
                             cg_lagged(0, 1e-6, 20).solver, steps));
  results.push_back(run_bullet(mesh, fixed, steps));
  std::printf("Linear static sag (fahr, one K u = f solve): %.3f mm\n\n",
              linear_static_sag_mm(mesh, fixed));
  std::printf(
      "| solver | CPU ms/step | max displacement mm | vs converged fahr %% | finite "
      "|\n|---|---|---|---|---|\n");
  for (const PeerResult& r : results) {
    std::printf("| %s | %.2f | %.3f | %+.2f | %s |\n", r.name.c_str(), r.cpu_ms, r.sag_mm,
                100.0 * (r.sag_mm - reference.sag_mm) / reference.sag_mm, r.finite ? "yes" : "NO");
  }
  for (const PeerResult& r : results) {
    if (!r.trace.empty())
      std::printf("\n%s: max displacement every 25 steps (mm):%s\n", r.name.c_str(),
                  r.trace.c_str());
  }
  return 0;
}
