// The gateway's scripted hands against the neonatal anatomy: walking the
// blade along each script (tissue at rest, no forces), how deep do its
// surface samples go into each rigid body? A script that drives the blade
// through bone would only measure how hard the proxy is pulled against it.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <string>

#include "fahr/collision/surface_samples.h"
#include "fahr/device/trajectory.h"
#include "scene_fixture.h"

namespace fahr::haptic_service::test {
namespace {

// Grazing the lips is part of an intubation; going into bone is not.
constexpr double kMaxDepthM = 0.5e-3;

std::map<std::string, double> deepest_along(const HapticSetup& setup,
                                            const device::Trajectory& script) {
  std::map<std::string, double> deepest;
  std::vector<collision::SurfaceContact> contacts(1024);
  const double end_s = script.keyframes().back().time_s;
  for (double t = 0.0; t <= end_s; t += 0.01) {
    const auto point = script.at(std::chrono::duration<double>(t));
    const Eigen::Isometry3d world_from_tool =
        Eigen::Translation3d(point.position_m) * point.orientation;
    for (const std::size_t a : setup.tool_obstacles) {
      std::size_t n = 0;
      collision::query_surface_samples(setup.tool_samples, world_from_tool,
                                       rigid_body(*setup.anatomy[a]), 0.0, contacts, n);
      double& d = deepest[setup.anatomy[a]->scene_body->name];
      for (std::size_t i = 0; i < n; ++i) d = std::max(d, contacts[i].depth_m);
    }
  }
  return deepest;
}

TEST(ScriptClearance, IntubationKeepsTheBladeOutOfTheAnatomy) {
  const HapticSetup& setup = neonatal_scene().setup;
  ASSERT_FALSE(setup.tool_obstacles.empty());
  // (The overshoot script's hand aims 59 mm below the tongue's surface on
  // purpose: the tissue and the force-aware freeze stop the blade, not the
  // script. Its path is the intubation's up to the press.)
  for (const auto& [body, depth] : deepest_along(setup, device::intubation_script())) {
    std::printf("intubation script: deepest into %s %.2f mm\n", body.c_str(), 1e3 * depth);
    EXPECT_LE(depth, kMaxDepthM) << "the intubation script drives the blade into " << body;
  }
}

}  // namespace
}  // namespace fahr::haptic_service::test
