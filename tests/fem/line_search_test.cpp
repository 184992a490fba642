// The line search of the Stable Neo-Hookean step (Body::search_line). A
// factorisation computed beside the step (SolverSettings::
// background_factor_latency_s) lags the tangent by its latency; a tissue that
// stiffens faster than the factor follows (a bar crushed along its axis and
// sheared, the load switched on and off every 100 ms) sees a lagged A softer
// than its own, and the full linearised step overshoots. Without the search
// the same bar leaves every finite number behind within the 400 steps; with
// it, the lagged step bends the bar as far as the exact step does.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "scenes.h"

namespace fahr::fem {
namespace {

struct Crush {
  double worst_displacement_m = 0.0;
  double final_displacement_m = 0.0;
  bool finite = true;
  int shortened_steps = 0;
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
    const StepReport report = body->step();
    out.shortened_steps += report.line_search_halvings > 0 ? 1 : 0;
    out.finite = out.finite && test::all_finite(*body);
    if (!out.finite) break;
    out.worst_displacement_m = std::max(out.worst_displacement_m, test::max_displacement(*body));
  }
  out.final_displacement_m = test::max_displacement(*body);
  return out;
}

TEST(LineSearch, TheLaggedStepBendsTheCrushedBarAsTheExactStepDoes) {
  for (const double load : {10.0, 20.0}) {
    const Crush exact = crush(load, true);
    const Crush lagged = crush(load, false);
    std::printf(
        "[ info ] %.0f body weights: worst displacement exact %.1f mm, lagged %.1f mm; "
        "steps shortened exact %d, lagged %d of 400\n",
        load, 1e3 * exact.worst_displacement_m, 1e3 * lagged.worst_displacement_m,
        exact.shortened_steps, lagged.shortened_steps);
    ASSERT_TRUE(exact.finite);
    ASSERT_TRUE(lagged.finite);
    // The bar is 30 mm long: bent over, never flung.
    EXPECT_LT(exact.worst_displacement_m, 0.1);
    EXPECT_LT(lagged.worst_displacement_m, 0.1);
    EXPECT_NEAR(lagged.worst_displacement_m, exact.worst_displacement_m, 0.002);
    // The search acts where the lag overshoots, not on the exact step.
    EXPECT_GT(lagged.shortened_steps, 0);
  }
}

// A body settling under gravity on its exact factor: every full step goes
// downhill, so the search leaves the step alone.
TEST(LineSearch, LeavesTheExactStepAlone) {
  const BodyMesh mesh = test::bar_mesh(2);
  BodySettings settings;
  settings.time_step = std::chrono::duration<double>(0.005);
  settings.sleep.enabled = false;
  settings.material.model = MaterialModel::kStableNeoHookean;
  settings.material.youngs_modulus_pa = 10000.0;
  settings.solver.refactor_period = 1;
  auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
  ASSERT_NE(body, nullptr);
  for (int k = 0; k < 200; ++k) EXPECT_EQ(body->step().line_search_halvings, 0) << "step " << k;
}

}  // namespace
}  // namespace fahr::fem
