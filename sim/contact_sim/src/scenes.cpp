// Shared test scenes.
#include "fahr/contact/sim/scenes.h"

#include <cmath>
#include <numbers>

namespace fahr::contact::sim {

fem::BodySettings block_body_settings(double fem_period_s) {
  fem::BodySettings s;
  s.material = fem::neonatal_tongue();
  s.time_step = std::chrono::duration<double>(fem_period_s);
  s.gravity_m_per_s2 = Eigen::Vector3d::Zero();
  // The rest factorisation, once: W never changes, which keeps a 1 kHz FEM
  // affordable in the tests; the static equilibrium is unchanged (body.h).
  s.solver.refactor_period = 0;
  return s;
}

PunchScene make_punch_scene(double punch_radius_m, double fem_period_s, std::string& error,
                            const PunchMesh& mesh, bool recompute_compliance) {
  PunchScene scene;
  const double a = punch_radius_m;
  GradedBlockSpec spec;
  spec.fine_cell_m = a / mesh.cells_per_radius;
  spec.half_width_m = mesh.block_radii * a;
  spec.depth_m = mesh.block_radii * a;
  spec.fine_half_width_m = 1.6 * a;
  spec.fine_depth_m = 1.2 * a;
  spec.growth = mesh.growth;
  scene.block = make_graded_block(spec);
  scene.punch_radius_m = a;
  for (const std::uint32_t node : scene.block.top_nodes) {
    const Eigen::Vector3d& p = scene.block.mesh.nodes_m[node];
    if (std::hypot(p.x(), p.z()) <= a + 1e-9) scene.sphere_nodes.push_back(node);
  }
  scene.effective_radius_m =
      spec.fine_cell_m *
      std::sqrt(static_cast<double>(scene.sphere_nodes.size()) / std::numbers::pi);
  std::vector<std::uint32_t> ids(scene.sphere_nodes.size());
  for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<std::uint32_t>(i);
  FemDriverSettings settings;
  settings.body = block_body_settings(fem_period_s);
  if (recompute_compliance) settings.body.solver.refactor_period = 1;
  scene.fem =
      FemDriver::create(settings, scene.block.mesh, scene.block.fixed_nodes,
                        make_node_spheres(scene.sphere_nodes, scene.sphere_radius_m), ids, error);
  return scene;
}

SmallScene make_small_scene(double fem_period_s, std::string& error) {
  SmallScene scene;
  GradedBlockSpec spec;
  spec.fine_cell_m = 0.004;
  spec.half_width_m = 0.010;
  spec.depth_m = 0.008;
  spec.fine_half_width_m = 0.010;
  spec.fine_depth_m = 0.008;
  spec.growth = 1.0;
  scene.block = make_graded_block(spec);
  // 6 x 2 x 6 cells, 432 tets; the 7 x 7 top nodes all fit the compliance
  // capacity of a DeformationState (64).
  std::vector<std::uint32_t> ids(scene.block.top_nodes.size());
  for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<std::uint32_t>(i);
  FemDriverSettings settings;
  settings.body = block_body_settings(fem_period_s);
  scene.fem = FemDriver::create(settings, scene.block.mesh, scene.block.fixed_nodes,
                                make_node_spheres(scene.block.top_nodes, 0.001), ids, error);
  return scene;
}

}  // namespace fahr::contact::sim
