// Scale (ms per step against mesh size), compliance block cost and error,
// and the 5k-tet rate target.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bench_util.h"

namespace fahr::fem::bench {
namespace {

constexpr double kBoxSide_m = 0.04;  // a tongue-sized block, 40 mm

struct Size {
  const char* label;
  std::array<int, 3> cells;
  int steps;
};

BodyMesh block(const Size& size) {
  const double cell = kBoxSide_m / size.cells[0];
  return make_box_mesh(size.cells,
                       Eigen::Vector3d(kBoxSide_m, cell * size.cells[1], cell * size.cells[2]));
}

std::unique_ptr<Body> block_body(const BodyMesh& mesh, const SolverSettings& solver,
                                 double step_s) {
  BodySettings settings;
  settings.time_step = std::chrono::duration<double>(step_s);
  settings.solver = solver;
  settings.sleep.enabled = false;
  BodyOrError made =
      Body::create(settings, mesh.nodes_m, mesh.tets, nodes_where_y_below(mesh, 1e-9));
  if (!made.error.empty()) std::fprintf(stderr, "block: %s\n", made.error.c_str());
  return std::move(made.body);
}

// Spheres on the top layer: one per top tet (weights 1/4), in order.
SphereLinks top_spheres(const BodyMesh& mesh, std::size_t count) {
  double top = -1e9;
  for (const auto& p : mesh.nodes_m) top = std::max(top, p.y());
  SphereLinks links;
  const std::array<double, 4> w = {0.25, 0.25, 0.25, 0.25};
  for (std::size_t e = 0; e < mesh.tets.size() && links.size() < count; ++e) {
    // Tets with a node on the top face (the surface a tool presses).
    double highest = -1e9;
    for (const auto n : mesh.tets[e]) highest = std::max(highest, mesh.nodes_m[n].y());
    if (highest > top - 1e-9) links.add_sphere(mesh.tets[e], w, 0.001);
  }
  return links;
}

std::vector<Size> sizes(bool quick) {
  std::vector<Size> list = {
      {"1k", {5, 7, 5}, 200}, {"5k", {9, 10, 9}, 100}, {"20k", {15, 15, 15}, 30}};
  if (!quick) list.push_back({"80k", {24, 23, 24}, 8});
  return list;
}

std::vector<SolverCase> scale_cases() {
  return {cholmod_exact(),      cholmod_lagged(10),      cholmod_lagged(0),
          cg_jacobi(1e-4, 100), cg_lagged(10, 1e-6, 10), cg_lagged(0, 1e-6, 10)};
}

std::vector<SolverCase> target_cases() {
  std::vector<SolverCase> cases = scale_cases();
  for (const auto factor : {CholmodFactorKind::kSimplicial, CholmodFactorKind::kSupernodal}) {
    for (const auto ordering : {CholmodOrdering::kAmd, CholmodOrdering::kMetis}) {
      if (factor == CholmodFactorKind::kSupernodal && ordering == CholmodOrdering::kMetis)
        continue;  // the default
      SolverCase c = cholmod_lagged(10);
      c.solver.cholmod.factor = factor;
      c.solver.cholmod.ordering = ordering;
      c.name += factor == CholmodFactorKind::kSimplicial ? ", simplicial" : ", supernodal";
      c.name += ordering == CholmodOrdering::kAmd ? " AMD" : " METIS";
      cases.push_back(c);
    }
  }
  SolverCase warped = cg_lagged(0, 1e-6, 10);
  warped.solver.warp_lagged_factor = true;
  warped.name += ", warped";
  cases.push_back(warped);
  cases.push_back(cg_lagged(0, 1e-4, 10));
  cases.push_back(cg_lagged(50, 1e-6, 10));
  cases.push_back(cholmod_lagged(50));
  SolverCase no_rotation = cholmod_lagged(0);
  no_rotation.solver.refactor_rotation_rad = 0.0;
  no_rotation.name = "cholmod rest factor only (unsafe past ~0.3 rad, see tests)";
  cases.push_back(no_rotation);
  return cases;
}

}  // namespace

void run_scale(bool quick) {
  std::printf(
      "\n## Scale: 40 mm tongue-material block, bottom fixed, gravity, h = 2 ms, one core\n\n");
  std::printf(
      "| mesh | tets | DOF | L non-zeros | solver | CPU ms/step | wall ms/step | max wall ms | CG "
      "it/step | refactorisations |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Size& size : sizes(quick)) {
    const BodyMesh mesh = block(size);
    for (const SolverCase& c : scale_cases()) {
      const auto start = Clock::now();
      auto body = block_body(mesh, c.solver, 0.002);
      if (!body) continue;
      const double setup_ms = ms_since(start);
      const StepTiming t = time_steps(*body, 3, size.steps);
      std::printf(
          "| %s | %zu | %zu | %.3g | %s | %.3f | %.3f | %.3f | %.1f | %d of %d (set-up %.0f ms) "
          "|\n",
          size.label, mesh.tets.size(), 3 * mesh.nodes_m.size(), body->factor_nonzeros(),
          c.name.c_str(), t.mean_cpu_ms, t.mean_ms, t.max_ms, t.mean_iterations, t.refactorisations,
          size.steps, setup_ms);
      std::fflush(stdout);
    }
  }
}

void run_compliance(bool quick) {
  // Spheres new to the block (each window of k taken from more top spheres
  // than the block keeps, so none is kept when its window comes back) and
  // spheres kept (the same window again: W from the kept columns alone);
  // full solves A^-1 J^T on a simplicial factor against half solves
  // L^-1 P J^T on a supernodal one (compliance.h), the same A.
  std::printf("\n## Compliance block W = h^2 J A^-1 J^T: cost against candidate contacts\n\n");
  std::printf(
      "| mesh | tets | factor | L non-zeros | k spheres | W size | CPU ms, k new spheres | CPU ms, "
      "k kept |\n|---|---|---|---|---|---|---|---|\n");
  for (const Size& size : sizes(quick)) {
    if (std::string(size.label) == "80k") continue;
    const BodyMesh mesh = block(size);
    for (const CholmodFactorKind kind :
         {CholmodFactorKind::kSimplicial, CholmodFactorKind::kSupernodal}) {
      SolverSettings solver = cholmod_exact().solver;
      solver.cholmod.factor = kind;
      auto body = block_body(mesh, solver, 0.002);
      const SphereLinks links = top_spheres(mesh, 512);
      body->step();
      for (const std::size_t k :
           {std::size_t{1}, std::size_t{8}, std::size_t{32}, std::size_t{64}}) {
        // Windows over at least 256 spheres: more than the 96 the block keeps.
        const std::size_t windows = std::max<std::size_t>(4, 256 / k);
        if (k * windows > links.size()) continue;
        std::vector<std::uint32_t> ids(k);
        std::vector<float> w(9 * k * k);
        const auto window = [&](std::size_t which) {
          for (std::size_t s = 0; s < k; ++s) ids[s] = static_cast<std::uint32_t>(which * k + s);
          body->compliance(ids, links, w);
        };
        for (std::size_t r = 0; r < windows; ++r) window(r);  // sizes CHOLMOD's buffers
        const std::size_t repeats = 2 * windows;
        double cpu_start = thread_cpu_ms();
        for (std::size_t r = 0; r < repeats; ++r) window(r % windows);
        const double fresh_ms = (thread_cpu_ms() - cpu_start) / double(repeats);
        window(0);  // solved again if the last windows pushed it out
        cpu_start = thread_cpu_ms();
        for (std::size_t r = 0; r < repeats; ++r) window(0);
        const double kept_ms = (thread_cpu_ms() - cpu_start) / double(repeats);
        std::printf("| %s | %zu | %s | %.0f | %zu | %zu x %zu | %.3f | %.3f |\n", size.label,
                    mesh.tets.size(),
                    kind == CholmodFactorKind::kSupernodal ? "supernodal, half solves"
                                                           : "simplicial, full solves",
                    body->factor_nonzeros(), k, 3 * k, 3 * k, fresh_ms, kept_ms);
      }
    }
  }

  // Error of W from a lagged factorisation: the block pressed 5 mm down by 8
  // frozen contacts for 0.2 s, W of those 8 spheres from the rest factor and
  // from a factor of the current A, with identical trajectories (CG to 1e-10).
  std::printf(
      "\n### Error of W from a lagged factorisation (5k block pressed 5 mm by 8 frozen "
      "contacts)\n\n");
  std::printf(
      "| factor (CG to 1e-10 on the current A, so the trajectories agree) | relative Frobenius "
      "error of W | "
      "worst diagonal error %% |\n|---|---|---|\n");
  const BodyMesh mesh = block(sizes(true)[1]);
  const SphereLinks links = top_spheres(mesh, 8);
  std::vector<std::uint32_t> ids(links.size());
  for (std::size_t s = 0; s < ids.size(); ++s) ids[s] = static_cast<std::uint32_t>(s);
  auto exact = block_body(mesh, cholmod_exact().solver, 0.002);
  std::vector<float> w_exact(9 * ids.size() * ids.size());
  std::vector<std::pair<std::string, std::unique_ptr<Body>>> lagged;
  auto lagged_case = [&](const std::string& name, int period, double rotation_rad, bool warp) {
    SolverSettings solver = cg_lagged(period, 1e-10, 200).solver;
    solver.refactor_rotation_rad = rotation_rad;
    solver.warp_lagged_factor = warp;
    lagged.emplace_back(name, block_body(mesh, solver, 0.002));
  };
  lagged_case("rest matrix only", 0, 0.0, false);
  lagged_case("rest matrix only, warped per node", 0, 0.0, true);
  lagged_case("refreshed every 50 steps (7 steps old)", 50, 0.0, false);
  lagged_case("refreshed every 10 steps (7 steps old)", 10, 0.0, false);
  lagged_case("refreshed on 0.1 rad of element rotation", 0, 0.1, false);
  ContactSet set;
  for (std::uint32_t s = 0; s < links.size(); ++s) {
    Contact c;
    c.sphere_id = s;
    c.state = ContactState::kFrozen;
    c.hold_centre_m = links.centre(s, exact->positions_m().data()) - Eigen::Vector3d(0, 0.005, 0);
    set.contacts.push_back(c);
  }
  // 107 steps: the /10 and /50 factors are then 7 steps old.
  for (int k = 0; k < 107; ++k) {
    set.state_step = exact->step_index();
    exact->step(&set, &links);
    for (auto& [name, body] : lagged) body->step(&set, &links);
  }
  exact->compliance(ids, links, w_exact);
  for (auto& [name, body] : lagged) {
    std::vector<float> w(w_exact.size());
    body->compliance(ids, links, w);
    double diff = 0.0, norm = 0.0, worst_diagonal = 0.0;
    const std::size_t rows = 3 * ids.size();
    for (std::size_t i = 0; i < w.size(); ++i) {
      diff += std::pow(static_cast<double>(w[i]) - static_cast<double>(w_exact[i]), 2);
      norm += std::pow(static_cast<double>(w_exact[i]), 2);
    }
    for (std::size_t i = 0; i < rows; ++i) {
      const double e = w_exact[i * rows + i];
      worst_diagonal =
          std::max(worst_diagonal, std::abs(static_cast<double>(w[i * rows + i]) - e) / e);
    }
    std::printf("| %s | %.2e | %.3f |\n", name.c_str(), std::sqrt(diff / norm),
                100.0 * worst_diagonal);
  }
}

void run_target() {
  std::printf(
      "\n## Target: 5k-tet body at >= 500 steps/s on one core (h = 2 ms, 8 active contacts)\n\n");
  std::printf(
      "| solver | CPU ms/step | wall ms/step | max wall ms | steps/s (CPU) | CG it/step | "
      "refactorisations | "
      "L non-zeros | meets 500/s |\n|---|---|---|---|---|---|---|---|---|\n");
  const BodyMesh mesh = block(sizes(true)[1]);
  const SphereLinks links = top_spheres(mesh, 8);
  for (const SolverCase& c : target_cases()) {
    auto body = block_body(mesh, c.solver, 0.002);
    ContactSet set;
    for (std::uint32_t s = 0; s < links.size(); ++s) {
      Contact contact;
      contact.sphere_id = s;
      contact.state = ContactState::kActive;
      contact.normal = Eigen::Vector3d(0, -1, 0);
      contact.plane_point_m =
          links.centre(s, body->positions_m().data()) + Eigen::Vector3d(0, 0.002, 0);
      set.contacts.push_back(contact);
    }
    const int steps = 500;
    double total = 0.0, worst = 0.0, iterations = 0.0, cpu_start = 0.0;
    int refactorisations = 0;
    for (int k = 0; k < steps + 5; ++k) {
      if (k == 5) cpu_start = thread_cpu_ms();
      // The plane moves down into the block at 10 mm/s: a tool pressing.
      for (Contact& contact : set.contacts) contact.plane_point_m.y() -= 0.002 * 0.01;
      set.state_step = body->step_index();
      const auto start = Clock::now();
      const StepReport report = body->step(&set, &links);
      const double ms = ms_since(start);
      if (k < 5) continue;
      refactorisations += report.refactorised ? 1 : 0;
      total += ms;
      worst = std::max(worst, ms);
      iterations += report.solver_iterations;
    }
    const double mean = total / steps;
    const double cpu = (thread_cpu_ms() - cpu_start) / steps;
    std::printf("| %s | %.3f | %.3f | %.3f | %.0f | %.1f | %d | %.3g | %s |\n", c.name.c_str(), cpu,
                mean, worst, 1000.0 / cpu, iterations / steps, refactorisations,
                body->factor_nonzeros(), 1000.0 / cpu >= 500.0 ? "yes" : "no");
  }
}

}  // namespace fahr::fem::bench
