// Omitted keys take the values of defaults.h; units, poses and durations are
// converted to SI and std::chrono on the way in.
#include "fahr/scene/defaults.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "test_support.h"

namespace fahr::scene::test {
namespace {

using namespace std::chrono_literals;

TEST(SceneDefaults, MinimalSceneGetsEveryDefault) {
  const auto scene = parse(kMinimalScene);
  EXPECT_EQ(scene->name, "minimal");
  EXPECT_EQ(scene->run.mode, RunMode::kRealtime);
  EXPECT_EQ(scene->run.duration, 0ns);
  EXPECT_EQ(scene->run.spin_wait, kDefaultSpinWait);
  EXPECT_EQ(scene->dds.vendor, DdsVendor::kCycloneDds);
  EXPECT_EQ(scene->dds.domain_id, kDefaultDomainId);
  EXPECT_EQ(scene->rates.haptic_hz, kDefaultHapticHz);
  EXPECT_EQ(scene->rates.fem_hz, kDefaultFemHz);
  EXPECT_EQ(scene->rates.status_hz, kDefaultStatusHz);
  EXPECT_EQ(scene->rates.haptic_period(), 1ms);
  EXPECT_EQ(scene->rates.fem_period(), 5ms);
  EXPECT_EQ(scene->gravity_mps2, Eigen::Vector3d(0.0, -9.81, 0.0));

  ASSERT_EQ(scene->bodies.size(), 4u);
  const Body& tongue = scene->bodies[0];
  ASSERT_TRUE(tongue.deformable.has_value());
  EXPECT_FALSE(tongue.rigid.has_value());
  EXPECT_EQ(tongue.id, 1u);  // position + 1
  EXPECT_EQ(tongue.deformable->material.youngs_modulus_pa, kDefaultYoungsModulusPa);
  EXPECT_EQ(tongue.deformable->material.poisson_ratio, kDefaultPoissonRatio);
  EXPECT_EQ(tongue.deformable->material.density_kg_per_m3, kDefaultDensityKgPerM3);
  EXPECT_EQ(tongue.deformable->material.rayleigh_mass_per_s, kDefaultRayleighMassPerS);
  EXPECT_EQ(tongue.deformable->material.rayleigh_stiffness_s, kDefaultRayleighStiffnessS);
  EXPECT_TRUE(tongue.deformable->fixed.nodes_file.empty());
  EXPECT_FALSE(tongue.deformable->fixed.box.has_value());
  EXPECT_EQ(tongue.deformable->aist.sphere_tet_volume_ratio, kDefaultSphereTetVolumeRatio);
  EXPECT_EQ(tongue.deformable->aist.refinement_levels, kDefaultRefinementLevels);
  EXPECT_EQ(tongue.deformable->aist.surface_spheres, kDefaultSurfaceSpheres);
  EXPECT_EQ(tongue.deformable->aist.sphere_budget, kDefaultSphereBudget);
  EXPECT_TRUE(tongue.pose.position_m.isZero());
  EXPECT_TRUE(tongue.pose.orientation.isApprox(Eigen::Quaterniond::Identity()));
  ASSERT_TRUE(scene->bodies[1].rigid.has_value());
  EXPECT_EQ(scene->bodies[1].rigid->sdf_cell_m, kDefaultSdfCellM);

  ASSERT_TRUE(scene->device.has_value());
  EXPECT_EQ(scene->device->backend, DeviceBackend::kSimulated);
  EXPECT_EQ(scene->device->model, DeviceModel::kTouchX);
  EXPECT_EQ(scene->device->tool_body, 1u);  // the only tool, found without device.tool
  EXPECT_EQ(scene->device->script, DeviceScript::kIntubation);
  EXPECT_FALSE(scene->device->limits.peak_force_n.has_value());
  EXPECT_EQ(scene->device->motion_scale, kDefaultMotionScale);

  EXPECT_EQ(scene->solver.linear_solver, LinearSolver::kCholmod);
  EXPECT_EQ(scene->solver.cg_tolerance, kDefaultCgTolerance);
  EXPECT_EQ(scene->solver.cg_max_iterations, kDefaultCgMaxIterations);
  EXPECT_EQ(scene->solver.projection_max_iterations, kDefaultProjectionMaxIterations);
  EXPECT_EQ(scene->solver.projection_tolerance_m, kDefaultProjectionToleranceM);
  EXPECT_EQ(scene->solver.compliance, ComplianceMode::kExact);
  EXPECT_EQ(scene->solver.compliance_columns, ComplianceColumns::kBlocks);
  EXPECT_EQ(scene->solver.max_candidate_contacts, kDefaultMaxCandidateContacts);
  EXPECT_EQ(scene->solver.volume_floor_ratio, 0.0);
  EXPECT_EQ(scene->solver.max_contact_age, kDefaultMaxContactAge);

  EXPECT_EQ(scene->contact.response, ContactResponse::kForceAware);
  EXPECT_EQ(scene->contact.coupling_stiffness_npm, kDefaultCouplingStiffnessNPerM);
  EXPECT_EQ(scene->contact.coupling_damping_nspm, kDefaultCouplingDampingNsPerM);
  EXPECT_EQ(scene->contact.force_aware_hysteresis, kDefaultForceAwareHysteresis);
  EXPECT_EQ(scene->contact.deformable_obstacle_margin_m, kDefaultDeformableObstacleMarginM);
  EXPECT_TRUE(scene->contact.include_pairs.empty());
  EXPECT_TRUE(scene->contact.tool_stops_at_anatomy);
  EXPECT_EQ(scene->contact.held_proxy, HeldProxy::kLoad);
  EXPECT_TRUE(scene->qos.empty());
}

TEST(SceneDefaults, MeshUnitsBecomeScales) {
  const auto scene = parse(kMinimalScene);
  EXPECT_EQ(scene->bodies[0].mesh_unit, LengthUnit::kMillimetre);
  EXPECT_DOUBLE_EQ(scene->bodies[0].mesh_scale, 0.001);
  EXPECT_DOUBLE_EQ(scene->bodies[2].mesh_scale, 0.01);
  EXPECT_DOUBLE_EQ(scene->bodies[3].mesh_scale, 1.0);
}

TEST(SceneDefaults, MeshPathsResolveAgainstTheSceneFolder) {
  const auto scene = parse(replaced("mesh: blade.obj", "mesh: ../meshes/./blade.obj"));
  EXPECT_EQ(scene->bodies[1].mesh_path, std::filesystem::path("/meshes/blade.obj"));
  EXPECT_EQ(scene->bodies[1].mesh_uri, "../meshes/./blade.obj");
  EXPECT_EQ(scene->bodies[0].mesh_path, std::filesystem::path("/scene/tongue.node"));
}

TEST(SceneDefaults, RollPitchYawIsFixedAxesXyz) {
  const auto scene = parse(replaced("unit: m\n",
                                    "unit: m\n    pose:\n      position_m: [0.01, 0.02, -0.03]\n"
                                    "      orientation_rpy_deg: [0, 0, 90]\n"));
  const Pose& pose = scene->bodies[3].pose;
  EXPECT_TRUE(pose.position_m.isApprox(Eigen::Vector3d(0.01, 0.02, -0.03)));
  // Yaw 90 degrees turns x into y.
  EXPECT_TRUE((pose.orientation * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
  // Roll is applied first: roll 90 then yaw 90 sends y to z, then z stays z.
  const Eigen::Quaterniond q = quaternion_from_rpy_deg(90.0, 0.0, 90.0);
  EXPECT_TRUE((q * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE((q * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY()));
}

TEST(SceneDefaults, QuaternionIsNormalised) {
  const auto scene = parse(replaced(
      "unit: m\n", "unit: m\n    pose:\n      orientation_quat_wxyz: [0.7071, 0, 0, 0.7071]\n"));
  const Eigen::Quaterniond& q = scene->bodies[3].pose.orientation;
  EXPECT_NEAR(q.norm(), 1.0, 1e-15);
  EXPECT_TRUE((q * Eigen::Vector3d::UnitX()).isApprox(Eigen::Vector3d::UnitY(), 1e-9));
}

TEST(SceneDefaults, LockstepBasePeriodDefaultsToTheFastestRate) {
  const auto scene = parse(std::string(kMinimalScene) +
                           "rates:\n  haptic_hz: 500\n  fem_hz: 100\nrun:\n  mode: lockstep\n"
                           "  duration_s: 2.5\n");
  EXPECT_EQ(scene->run.mode, RunMode::kLockstep);
  EXPECT_EQ(scene->run.base_period, 2ms);
  EXPECT_EQ(scene->run.duration, 2500ms);
  EXPECT_EQ(scene->run.fem_state_delay_steps, kDefaultFemStateDelaySteps);
  const auto explicit_base = parse(std::string(kMinimalScene) +
                                   "run:\n  mode: lockstep\n  base_period_ms: 0.5\n"
                                   "  fem_state_delay_steps: 0\n");
  EXPECT_EQ(explicit_base->run.base_period, 500us);
  EXPECT_EQ(explicit_base->run.fem_state_delay_steps, 0);
}

TEST(SceneDefaults, ExplicitSettingsAreRead) {
  const auto scene =
      parse(replaced("  backend: simulated",
                     "  backend: openhaptics\n  tool: blade\n  limits:\n    peak_force_n: 3.3\n"
                     "    workspace_m: [0.16, 0.12, 0.07]\n  motion_scale: 2") +
            "solver:\n  linear_solver: pcg\n  cg_tolerance: 1e-8\n  cg_max_iterations: 50\n"
            "  compliance: lagged\n  compliance_columns: normals\n  max_contact_age_ms: 2.5\n"
            "  volume_floor_ratio: 0.6\n"
            "contact:\n  response: penalty\n  coupling_stiffness_npm: 250\n  "
            "tool_stops_at_anatomy: false\n  held_proxy: stay\n"
            "dds:\n  vendor: fastdds\n  domain_id: 42\n"
            "qos:\n  DevicePose: {deadline_ms: 2, reliability: best_effort}\n"
            "  ContactSet:\n    history_depth: 4\n");
  EXPECT_EQ(scene->device->backend, DeviceBackend::kOpenHaptics);
  EXPECT_EQ(scene->device->limits.peak_force_n, 3.3);
  EXPECT_FALSE(scene->device->limits.continuous_force_n.has_value());
  EXPECT_TRUE(scene->device->limits.workspace_m->isApprox(Eigen::Vector3d(0.16, 0.12, 0.07)));
  EXPECT_EQ(scene->device->motion_scale, 2.0);
  EXPECT_EQ(scene->solver.linear_solver, LinearSolver::kPcg);
  EXPECT_EQ(scene->solver.cg_tolerance, 1e-8);
  EXPECT_EQ(scene->solver.cg_max_iterations, 50);
  EXPECT_EQ(scene->solver.compliance, ComplianceMode::kLagged);
  EXPECT_EQ(scene->solver.compliance_columns, ComplianceColumns::kNormals);
  EXPECT_EQ(scene->solver.max_contact_age, 2500us);
  EXPECT_EQ(scene->solver.volume_floor_ratio, 0.6);
  EXPECT_EQ(scene->contact.response, ContactResponse::kPenalty);
  EXPECT_EQ(scene->contact.coupling_stiffness_npm, 250.0);
  EXPECT_FALSE(scene->contact.tool_stops_at_anatomy);
  EXPECT_EQ(scene->contact.held_proxy, HeldProxy::kStay);
  EXPECT_EQ(scene->dds.vendor, DdsVendor::kFastDds);
  EXPECT_EQ(scene->dds.domain_id, 42);
  ASSERT_EQ(scene->qos.size(), 2u);
  const QosOverride& pose_qos = scene->qos.at("DevicePose");
  EXPECT_EQ(pose_qos.deadline, std::chrono::nanoseconds(2ms));
  EXPECT_EQ(pose_qos.reliability, Reliability::kBestEffort);
  EXPECT_FALSE(pose_qos.history_depth.has_value());
  EXPECT_EQ(scene->qos.at("ContactSet").history_depth, 4);
}

TEST(SceneDefaults, FixedBoxIsRead) {
  const auto scene = parse(replaced(
      "    unit: mm\n  - name: blade",
      "    unit: mm\n    fixed:\n      box_m: {min: [-0.05, -0.03, -0.02], max: [0, -0.01, 0.02]}\n"
      "  - name: blade"));
  const auto& box = scene->bodies[0].deformable->fixed.box;
  ASSERT_TRUE(box.has_value());
  EXPECT_TRUE(box->contains(Eigen::Vector3d(-0.01, -0.02, 0.0)));
  EXPECT_FALSE(box->contains(Eigen::Vector3d(0.01, -0.02, 0.0)));
}

}  // namespace
}  // namespace fahr::scene::test
