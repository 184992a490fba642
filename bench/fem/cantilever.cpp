// Run time against error: a 100 x 10 x 10 mm cantilever under a tip load,
// against the Euler-Bernoulli deflection P L^3 / (3 E I).
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bench_util.h"

namespace fahr::fem::bench {
namespace {

constexpr double kLengthM = 0.1;
constexpr double kSideM = 0.01;
constexpr double kYoungsPa = 1e6;
constexpr double kPoisson = 0.3;
constexpr double kDensity = 1000.0;
// Tip deflection of 0.1 mm (L / 1000): small enough that geometric
// nonlinearity (which the corotated model has and Euler-Bernoulli lacks)
// stays below 1e-5 relative.
constexpr double kTargetDeflectionM = 1e-4;

double second_moment() {
  return kSideM * kSideM * kSideM * kSideM / 12.0;
}
double tip_load_n() {
  return 3.0 * kYoungsPa * second_moment() * kTargetDeflectionM / std::pow(kLengthM, 3);
}

struct Row {
  int n = 0;
  std::size_t tets = 0;
  std::size_t dofs = 0;
  std::string solver;
  double ms = 0.0;  // CPU time of the stepping thread per step
  double wall_ms = 0.0;
  double max_ms = 0.0;
  double iterations = 0.0;
  double deflection_m = 0.0;
  double error_pct = 0.0;
  bool pareto = false;
};

TetMesh beam(int n) {
  return make_box_mesh({10 * n, n, n}, Eigen::Vector3d(kLengthM, kSideM, kSideM));
}

Material beam_material(double rayleigh_mass) {
  Material m;
  m.youngs_modulus_pa = kYoungsPa;
  m.poisson_ratio = kPoisson;
  m.density_kg_per_m3 = kDensity;
  m.rayleigh_mass_per_s = rayleigh_mass;
  m.rayleigh_stiffness_s = 0.0;
  return m;
}

std::unique_ptr<Body> loaded_beam(const TetMesh& mesh, const BodySettings& settings,
                                  std::vector<std::uint32_t>& tip) {
  std::vector<std::uint32_t> fixed;
  tip.clear();
  for (std::size_t i = 0; i < mesh.nodes_m.size(); ++i) {
    if (mesh.nodes_m[i].x() < 1e-9) fixed.push_back(static_cast<std::uint32_t>(i));
    if (mesh.nodes_m[i].x() > kLengthM - 1e-9) tip.push_back(static_cast<std::uint32_t>(i));
  }
  BodyOrError made = Body::create(settings, mesh.nodes_m, mesh.tets, fixed);
  if (!made.error.empty()) {
    std::fprintf(stderr, "beam: %s\n", made.error.c_str());
    return nullptr;
  }
  const Eigen::Vector3d per_node(0.0, -tip_load_n() / static_cast<double>(tip.size()), 0.0);
  for (const std::uint32_t node : tip) made.body->set_external_force(node, per_node);
  return std::move(made.body);
}

double tip_deflection(const Body& body, const std::vector<std::uint32_t>& tip) {
  double sum = 0.0;
  for (const std::uint32_t node : tip)
    sum += body.rest_position(node).y() - body.position(node).y();
  return sum / static_cast<double>(tip.size());
}

double euler_bernoulli() {
  return tip_load_n() * std::pow(kLengthM, 3) / (3.0 * kYoungsPa * second_moment());
}

// Linear static solution: one implicit step of h = 1000 s from rest without
// damping, which is K u = f up to a relative M / (h^2 K) ~ 1e-9.
double static_deflection(const TetMesh& mesh, double& ms) {
  BodySettings settings;
  settings.material = beam_material(0.0);
  settings.gravity_m_per_s2.setZero();
  settings.time_step = std::chrono::duration<double>(1000.0);
  settings.sleep.enabled = false;
  std::vector<std::uint32_t> tip;
  const auto start = Clock::now();
  auto body = loaded_beam(mesh, settings, tip);
  if (!body) return NAN;
  body->step();
  ms = ms_since(start);
  return tip_deflection(*body, tip);
}

// Errors are compared as printed (0.001 %): differences below that are
// solver round-off, not accuracy.
double printed_error(const Row& row) {
  return std::round(std::abs(row.error_pct) * 1e3);
}

void mark_pareto(std::vector<Row>& rows) {
  for (Row& a : rows) {
    a.pareto = std::none_of(rows.begin(), rows.end(), [&](const Row& b) {
      return (b.ms <= a.ms && printed_error(b) < printed_error(a)) ||
             (b.ms < a.ms && printed_error(b) <= printed_error(a));
    });
  }
}

}  // namespace

void run_cantilever(int max_dynamic_n, int max_static_n, int steps) {
  const double reference = euler_bernoulli();
  // Critical damping of the first bending mode, so that `steps` steps of
  // 10 ms reach equilibrium when the solve is exact.
  const double area = kSideM * kSideM;
  const double omega1 =
      3.516 / (kLengthM * kLengthM) * std::sqrt(kYoungsPa * second_moment() / (kDensity * area));
  std::printf("\n## Cantilever: %g x %g x %g mm, E %g Pa, nu %g, tip load %.4g N\n", 1e3 * kLengthM,
              1e3 * kSideM, 1e3 * kSideM, kYoungsPa, kPoisson, tip_load_n());
  std::printf(
      "Euler-Bernoulli tip deflection P L^3/(3 E I) = %.6f mm. Mesh n: %d x n x n cells of 6 "
      "tets.\n",
      1e3 * reference, 10);
  std::printf("\n### Static linear solve per mesh (one CHOLMOD solve)\n\n");
  std::printf(
      "| n | tets | DOF | cell mm | deflection mm | error vs EB %% | set-up + solve ms |\n");
  std::printf("|---|---|---|---|---|---|---|\n");
  std::vector<double> cells, errors, deflections;
  std::vector<int> ns;
  for (int n = 2; n <= max_static_n; n += 2) {
    const TetMesh mesh = beam(n);
    double ms = 0.0;
    const double d = static_deflection(mesh, ms);
    const double error = 100.0 * (d - reference) / reference;
    std::printf("| %d | %zu | %zu | %.3f | %.6f | %+.3f | %.0f |\n", n, mesh.tets.size(),
                3 * mesh.nodes_m.size(), 10.0 / n, 1e3 * d, error, ms);
    ns.push_back(n);
    cells.push_back(kSideM / n);
    errors.push_back(std::abs(error));
    deflections.push_back(d);
  }
  // Least-squares slope of log |error| against log cell size.
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double m = static_cast<double>(cells.size());
  for (std::size_t i = 0; i < cells.size(); ++i) {
    const double x = std::log(cells[i]);
    const double y = std::log(errors[i]);
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
  }
  const double slope = (m * sxy - sx * sy) / (m * sxx - sx * sx);
  std::printf("\nObserved order of the error against EB (least squares over n): %.2f\n", slope);
  // Richardson on n, 2n, 4n where available (the 3-D solution is not EB's).
  for (std::size_t i = 0; i < ns.size(); ++i) {
    const auto j = std::find(ns.begin(), ns.end(), 2 * ns[i]);
    const auto k = std::find(ns.begin(), ns.end(), 4 * ns[i]);
    if (j == ns.end() || k == ns.end()) continue;
    const double d1 = deflections[i];
    const double d2 = deflections[static_cast<std::size_t>(j - ns.begin())];
    const double d4 = deflections[static_cast<std::size_t>(k - ns.begin())];
    const double p = std::log2((d2 - d1) / (d4 - d2));
    const double limit = d4 + (d4 - d2) / (std::pow(2.0, p) - 1.0);
    std::printf(
        "Richardson n = %d, %d, %d: order %.2f, extrapolated deflection %.6f mm (%+.3f %% vs EB)\n",
        ns[i], 2 * ns[i], 4 * ns[i], p, 1e3 * limit, 100.0 * (limit - reference) / reference);
  }

  std::printf(
      "\n### Stepping to rest: %d steps of 10 ms, critically damped first mode (alpha %.1f "
      "1/s)\n\n",
      steps, 2.0 * omega1);
  std::vector<SolverCase> cases = {
      cholmod_exact(),     cholmod_lagged(10),      cg_jacobi(1e-8, 2000), cg_jacobi(1e-8, 50),
      cg_jacobi(1e-8, 10), cg_lagged(10, 1e-8, 20), cg_lagged(0, 1e-8, 3), cg_lagged(0, 1e-8, 1)};
  // Fine meshes only with the solvers that stay affordable there (one
  // factorisation of the rest matrix; this load is a small deflection).
  const std::vector<SolverCase> fine_cases = {cholmod_lagged(0), cg_lagged(0, 1e-8, 3)};
  std::vector<Row> rows;
  for (const int n : {2, 4, 6, 8, 12, 16}) {
    if (n > max_dynamic_n) break;
    const TetMesh mesh = beam(n);
    for (const SolverCase& c : n > 8 ? fine_cases : cases) {
      BodySettings settings;
      settings.material = beam_material(2.0 * omega1);
      settings.gravity_m_per_s2.setZero();
      settings.time_step = std::chrono::milliseconds(10);
      settings.solver = c.solver;
      settings.sleep.enabled = false;
      std::vector<std::uint32_t> tip;
      auto body = loaded_beam(mesh, settings, tip);
      if (!body) continue;
      const StepTiming timing = time_steps(*body, 0, steps);
      std::fprintf(stderr, "  n %d %s done\n", n, c.name.c_str());
      Row row;
      row.n = n;
      row.tets = mesh.tets.size();
      row.dofs = 3 * mesh.nodes_m.size();
      row.solver = c.name;
      row.ms = timing.mean_cpu_ms;
      row.wall_ms = timing.mean_ms;
      row.max_ms = timing.max_ms;
      row.iterations = timing.mean_iterations;
      row.deflection_m = tip_deflection(*body, tip);
      row.error_pct = 100.0 * (row.deflection_m - reference) / reference;
      rows.push_back(row);
    }
  }
  mark_pareto(rows);
  std::printf("Pareto front over (CPU ms/step, |error|) across all meshes and solvers.\n\n");
  std::printf(
      "| n | tets | solver | CPU ms/step | wall ms/step | max wall ms | CG it/step | deflection mm "
      "| error vs EB %% | Pareto |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& r : rows) {
    std::printf("| %d | %zu | %s | %.3f | %.3f | %.3f | %.1f | %.6f | %+.3f | %s |\n", r.n, r.tets,
                r.solver.c_str(), r.ms, r.wall_ms, r.max_ms, r.iterations, 1e3 * r.deflection_m,
                r.error_pct, r.pareto ? "**front**" : "");
  }
}

}  // namespace fahr::fem::bench
