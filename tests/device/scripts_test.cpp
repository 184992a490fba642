// The simulated hand's scripts: every name chooses its script and no other
// name is taken; every script starts and ends at the scene's initial blade
// pose (where world_from_device puts the stylus), so the coupling pulls on
// nothing there.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <iterator>
#include <string>

#include "fahr/device/trajectory.h"

namespace {

using fahr::device::Script;
using fahr::device::Trajectory;
using Seconds = std::chrono::duration<double>;

constexpr double kPeakForceN = 7.9;
constexpr double kHandStiffnessNpm = 400.0;

double pitch_deg(const fahr::device::Quat& q) {
  const fahr::device::Vec3 x = q * fahr::device::Vec3::UnitX();
  return std::atan2(x.y(), x.x()) * 180.0 / 3.14159265358979323846;
}

TEST(Scripts, EveryNameChoosesItsScriptAndNoOther) {
  for (std::size_t i = 0; i < std::size(fahr::device::kScriptNames); ++i) {
    Script script{};
    ASSERT_TRUE(fahr::device::script_by_name(fahr::device::kScriptNames[i], script))
        << fahr::device::kScriptNames[i];
    EXPECT_EQ(static_cast<std::size_t>(script), i);
  }
  Script script = Script::kOvershoot;
  EXPECT_FALSE(fahr::device::script_by_name("Miller", script));
  EXPECT_FALSE(fahr::device::script_by_name("", script));
  EXPECT_EQ(script, Script::kOvershoot) << "a refused name must leave the choice alone";
}

TEST(Scripts, StartAndEndAtTheScenesInitialPose) {
  const fahr::device::Vec3 initial(0.012, 0.0005, 0.0);
  for (const auto name : fahr::device::kScriptNames) {
    Script script{};
    ASSERT_TRUE(fahr::device::script_by_name(name, script));
    const Trajectory t = fahr::device::script_trajectory(script, kPeakForceN, kHandStiffnessNpm);
    EXPECT_LT((t.at(Seconds(0.0)).position_m - initial).norm(), 1e-9) << name;
    EXPECT_LT((t.at(t.duration()).position_m - initial).norm(), 1e-9) << name;
    EXPECT_NEAR(pitch_deg(t.at(Seconds(0.0)).orientation), 0.0, 1e-9) << name;
    EXPECT_NEAR(pitch_deg(t.at(t.duration()).orientation), 0.0, 1e-9) << name;
  }
}

}  // namespace
