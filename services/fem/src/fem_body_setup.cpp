// Scene body -> FEM body and sphere links.
#include "fahr/fem_service/fem_body_setup.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "deformation_state.h"
#include "fahr/layout_links/fem_links.h"
#include "fahr/runtime/scene_bodies.h"
#include "fahr/sphere_layout/fill_spheres.h"

namespace fahr::fem_service {
namespace {

std::vector<std::uint32_t> fixed_nodes(const scene::Body& body, const geometry::TetMesh& mesh) {
  const auto& fixed = body.deformable->fixed;
  std::vector<std::uint32_t> nodes = fixed.node_indices;
  if (fixed.box) {
    for (std::uint32_t i = 0; i < mesh.node_count(); ++i) {
      if (fixed.box->contains(mesh.rest_positions()[i])) nodes.push_back(i);
    }
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  for (auto n : nodes) {
    if (n >= mesh.node_count()) {
      throw std::runtime_error("body '" + body.name + "': fixed node " + std::to_string(n) +
                               " is beyond the mesh's " + std::to_string(mesh.node_count()) +
                               " nodes (" + body.deformable->fixed.nodes_file.string() + ")");
    }
  }
  if (nodes.empty())
    throw std::runtime_error("body '" + body.name +
                             "': no fixed nodes; the tongue would fall away");
  return nodes;
}

fem::BodySettings body_settings(const scene::Scene& scene, const scene::Body& body) {
  fem::BodySettings s;
  const auto& m = body.deformable->material;
  s.material = {m.youngs_modulus_pa,
                m.poisson_ratio,
                m.density_kg_per_m3,
                m.rayleigh_mass_per_s,
                m.rayleigh_stiffness_s,
                m.yeoh_c20_over_c10,
                m.model == scene::MaterialModel::kStableNeoHookean
                    ? fem::MaterialModel::kStableNeoHookean
                    : fem::MaterialModel::kCorotational};
  s.time_step = std::chrono::duration<double>(1.0 / scene.rates.fem_hz);
  s.gravity_m_per_s2 = scene.gravity_mps2;
  s.solver.kind = scene.solver.linear_solver == scene::LinearSolver::kCholmod
                      ? fem::LinearSolver::kCholmod
                      : fem::LinearSolver::kConjugateGradient;
  // Reuse one factorisation and refresh it when an element has turned
  // 0.1 rad: 681 steps/s on a 5k-tet body where refactorising every step
  // gives 116 (bench/fem, `fem_bench target`); the force stays exact,
  // so the equilibrium does not change.
  s.solver.refactor_period = 0;
  if (s.solver.kind == fem::LinearSolver::kConjugateGradient) {
    // pcg: CG on the current A preconditioned by a lagged factorisation,
    // refreshed when a solve needs more than 12 iterations rather than on
    // the rotation trigger (Jacobi needs hundreds of iterations on stiff
    // systems); W comes from the lagged factor. On the pressed neonatal
    // tongue without the anatomy's support springs it refactorises in a
    // third to a half of the steps (the rotation trigger: nine in ten) but
    // the CG iterations and W's new columns eat the saving; the springs
    // refresh it whenever the held set changes (most pressed steps), so W
    // feels them. cholmod stays the neonatal scene's solver
    // (docs/design/fem-step-and-solvers.md, fem_tongue_press).
    s.solver.preconditioner = fem::CgPreconditioner::kLaggedCholesky;
    s.solver.refactor_rotation_rad = 0.0;
    s.solver.refactor_stiffening_change = 0.0;
    s.solver.refactor_deformation_change = 0.0;
    s.solver.cg_refresh_iterations = 12;
  }
  s.solver.background_factor_latency_s =
      std::chrono::duration<double>(scene.solver.factor_latency).count();
  s.solver.cg_relative_tolerance = scene.solver.cg_tolerance;
  s.solver.cg_max_iterations = scene.solver.cg_max_iterations;
  s.projection.max_sweeps = scene.solver.projection_max_iterations;
  s.projection.tolerance_m = scene.solver.projection_tolerance_m;
  const double age_steps =
      std::chrono::duration<double>(scene.solver.max_contact_age).count() * scene.rates.fem_hz;
  s.max_contact_age_steps = static_cast<std::uint64_t>(std::max(1.0, std::ceil(age_steps)));
  // A DeformationState carries W for at most msg::MAX_COMPLIANCE_SPHERES.
  s.max_compliance_spheres = std::min<std::size_t>(
      static_cast<std::size_t>(scene.solver.max_candidate_contacts), msg::MAX_COMPLIANCE_SPHERES);
  return s;
}

}  // namespace

FemBodySetup set_up_body(const scene::Scene& scene, const scene::Body& body,
                         fem::FactorInstall install) {
  FemBodySetup setup;
  setup.scene_body = &body;
  setup.mesh = runtime::world_tet_mesh(body);
  setup.fixed_nodes = fixed_nodes(body, setup.mesh);
  setup.settings = body_settings(scene, body);
  setup.settings.solver.factor_install = install;
  setup.compliance_along_normals =
      scene.solver.compliance_columns == scene::ComplianceColumns::kNormals;
  setup.volume_floor.ratio = scene.solver.volume_floor_ratio;
  const sphere_layout::SphereLayout layout =
      sphere_layout::fill_spheres(setup.mesh, runtime::fill_settings_for(body));
  setup.layout_fingerprint = layout.fingerprint();
  try {
    setup.links = layout_links::to_fem_links(layout);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("body '" + body.name + "': " + e.what());
  }
  std::vector<fem::Tet> tets;
  tets.reserve(setup.mesh.tet_count());
  for (const auto& t : setup.mesh.tets()) {
    tets.push_back({static_cast<std::uint32_t>(t[0]), static_cast<std::uint32_t>(t[1]),
                    static_cast<std::uint32_t>(t[2]), static_cast<std::uint32_t>(t[3])});
  }
  auto created =
      fem::Body::create(setup.settings, setup.mesh.rest_positions(), tets, setup.fixed_nodes);
  if (!created.body) throw std::runtime_error("body '" + body.name + "': " + created.error);
  setup.body = std::move(created.body);
  setup.anatomy = load_anatomy_fields(scene, body);
  return setup;
}

}  // namespace fahr::fem_service
