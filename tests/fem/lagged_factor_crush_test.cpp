// A factorisation computed beside the step (SolverSettings::
// background_factor_latency_s) lags the tangent by its latency. A tissue that
// stiffens faster than the factor follows (a Stable Neo-Hookean bar crushed
// along its axis and sheared, the load switched on and off every 100 ms)
// must still step as the exact implicit step does: while a refresh is under
// way the step solves the current A (Body::solve_velocity). Solved on the
// lagged factor alone, the same bar left every finite number behind within
// the 400 steps, where the exact step bends it 59 and 69 mm.
#include <gtest/gtest.h>

#include <algorithm>

#include "scenes.h"

namespace fahr::fem {
namespace {

struct Crush {
  double worst_displacement_m = 0.0;
  bool finite = true;
};

Crush crush(double load_in_body_weights, bool exact) {
  const BodyMesh mesh = test::bar_mesh(2);
  BodySettings settings;
  settings.gravity_m_per_s2.setZero();
  settings.time_step = std::chrono::duration<double>(0.005);  // the neonatal scene's 200 Hz
  settings.sleep.enabled = false;
  settings.material.model = MaterialModel::kStableNeoHookean;
  settings.material.youngs_modulus_pa = 10000.0;
  settings.material.yeoh_c20_over_c10 = kTongueYeohC20OverC10;
  // The neonatal scene's solver: a lagged factor refreshed when an element's
  // F moved by 0.1, computed beside the step and installed 30 ms later.
  settings.solver.refactor_period = exact ? 1 : 0;
  settings.solver.refactor_deformation_change = 0.1;
  settings.solver.background_factor_latency_s = exact ? 0.0 : 0.03;
  auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
  EXPECT_NE(body, nullptr);
  Crush out;
  if (!body) return out;
  const auto tip =
      test::nodes_where(mesh, [](const Eigen::Vector3d& p) { return p.x() > 0.03 - 1e-9; });
  const double per_node =
      load_in_body_weights * body->total_mass_kg() * 9.81 / static_cast<double>(tip.size());
  const Eigen::Vector3d push(-per_node, 0.3 * per_node, 0.0);
  for (int k = 0; k < 400; ++k) {
    if ((k / 20) % 2 == 0) {
      for (const std::uint32_t node : tip) body->set_external_force(node, push);
    } else {
      body->clear_external_forces();
    }
    body->step();
    out.finite = out.finite && test::all_finite(*body);
    if (!out.finite) break;
    out.worst_displacement_m = std::max(out.worst_displacement_m, test::max_displacement(*body));
  }
  return out;
}

TEST(LaggedFactor, StepsAsTheExactStepWhileTheTissueStiffens) {
  for (const double load : {10.0, 20.0}) {
    const Crush exact = crush(load, true);
    const Crush lagged = crush(load, false);
    std::printf("[ info ] %.0f body weights: worst displacement exact %.1f mm, lagged %.1f mm\n",
                load, 1e3 * exact.worst_displacement_m, 1e3 * lagged.worst_displacement_m);
    ASSERT_TRUE(exact.finite);
    ASSERT_TRUE(lagged.finite);
    // The bar is 30 mm long: bent over, never flung.
    EXPECT_LT(exact.worst_displacement_m, 0.1);
    EXPECT_NEAR(lagged.worst_displacement_m, exact.worst_displacement_m, 0.002);
  }
}

}  // namespace
}  // namespace fahr::fem
