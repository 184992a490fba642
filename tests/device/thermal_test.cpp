// The thermal model derates sustained force to the continuous limit and
// recovers the peak after cooling; bursts get the peak.
#include <gtest/gtest.h>

#include <cstdio>

#include "fahr/device/servo_core.h"
#include "fahr/device/thermal_model.h"
#include "test_support.h"

namespace fahr::test {
namespace {

using namespace std::chrono_literals;

TEST(Thermal, SustainedOverloadDeratesToContinuousAndRecovers) {
  const device::DeviceModel model = device::touch_x_model();
  device::ThermalModel thermal(model);
  EXPECT_EQ(thermal.renderable_force_n(), model.peak_force_n);
  // The hand demands 3x the peak: the device renders what it may.
  double burst_s = 0.0;
  const auto dt = std::chrono::duration<double>(1e-3);
  for (int i = 0; i < 300'000; ++i) {  // 300 s = 10 time constants
    if (thermal.renderable_force_n() >= model.peak_force_n) burst_s += 1e-3;
    thermal.update(std::min(3.0 * model.peak_force_n, thermal.renderable_force_n()), dt);
  }
  std::printf(
      "thermal: peak available for %.3f s from cold; after 300 s: %.4f N (continuous %.2f N), heat "
      "%.4f\n",
      burst_s, thermal.renderable_force_n(), model.continuous_force_n, thermal.heat());
  // Bursts get the peak for a while (below a second for tau 30 s, from cold) ...
  EXPECT_GT(burst_s, 0.3);
  EXPECT_LT(burst_s, 2.0);
  // ... sustained force settles at the continuous limit (within 1%: the
  // approach to h = 1 is asymptotic).
  EXPECT_LT(thermal.renderable_force_n(), 1.01 * model.continuous_force_n);
  EXPECT_GE(thermal.renderable_force_n(), model.continuous_force_n);
  // Released, it cools: the peak is back within a few time constants.
  double recovery_s = 0.0;
  while (thermal.renderable_force_n() < model.peak_force_n && recovery_s < 300.0) {
    thermal.update(0.0, dt);
    recovery_s += 1e-3;
  }
  std::printf("thermal: peak back after %.1f s at rest\n", recovery_s);
  EXPECT_EQ(thermal.renderable_force_n(), model.peak_force_n);
  EXPECT_LT(recovery_s, 60.0);
}

TEST(Thermal, ServoLoopPublishesTheDeratedLimitAndRendersWithinIt) {
  device::GatewayConfig config;
  config.safety.engage_cycles = 1;
  config.safety.engage_threshold_n = 1e9;
  ScriptedBackend backend;
  device::ServoCore core(config, backend);
  device::ForceCommandSample command;
  command.force_n = Vec3(0.0, 3.0 * config.model.peak_force_n, 0.0);  // the overshoot
  double last_renderable = 0.0;
  for (std::uint64_t t = 0; t < 120'000; ++t) {  // 120 s
    command.answered_pose_seq = t;
    const auto& pose = core.tick(tick_time(t), t > 0 ? &command : nullptr);
    EXPECT_LE(pose.rendered_force_n.norm(), pose.renderable_force_n + 1e-9);
    last_renderable = pose.renderable_force_n;
  }
  EXPECT_LT(last_renderable, 1.05 * config.model.continuous_force_n);
  EXPECT_LT(core.peak_rendered_force_n(), config.model.peak_force_n + 1e-9);
  EXPECT_GT(core.peak_rendered_force_n(), 0.99 * config.model.peak_force_n);
}

TEST(DeviceModel, DefaultsAreTheTouchXAndValidate) {
  const device::DeviceModel model = device::touch_x_model();
  EXPECT_EQ(device::validate(model), "");
  EXPECT_EQ(model.peak_force_n, 7.9);
  EXPECT_EQ(model.continuous_force_n, 1.75);
  device::DeviceModel bad = model;
  bad.continuous_force_n = 10.0;
  EXPECT_NE(device::validate(bad).find("continuous_force_n"), std::string::npos);
  device::DeviceModel other;
  EXPECT_TRUE(device::model_by_name("touch", other));
  EXPECT_EQ(device::validate(other), "");
  EXPECT_FALSE(device::model_by_name("falcon", other));
}

}  // namespace
}  // namespace fahr::test
