// Every class of scene error names the file, the line and column, the key
// path, and (for unknown keys) the valid keys with the nearest suggested.
#include <gtest/gtest.h>

#include <initializer_list>
#include <string>

#include "fahr/scene/scene_error.h"
#include "test_support.h"

namespace fahr::scene::test {
namespace {

void expect_contains(const std::string& message, std::initializer_list<std::string> parts) {
  for (const std::string& part : parts) {
    EXPECT_NE(message.find(part), std::string::npos) << "missing \"" << part << "\" in:\n"
                                                     << message;
  }
}

// The tongue's material, spliced in after its unit line.
std::string with_material(std::string_view material_lines) {
  return replaced(
      "    unit: mm\n  - name: blade",
      "    unit: mm\n    material:\n" + std::string(material_lines) + "  - name: blade");
}

TEST(SceneErrors, UnknownTopLevelKeyListsValidKeysAndSuggests) {
  const std::string text = std::string(kMinimalScene) + "gravty_mps2: [0, 0, -9.81]\n";
  expect_contains(
      error_of(text),
      {"test.yaml:22:1: gravty_mps2: unknown key 'gravty_mps2'", "did you mean 'gravity_mps2'?",
       "Valid keys here: format_version, name, description, run, dds, rates, "
       "gravity_mps2, bodies, device, solver, contact, qos"});
}

TEST(SceneErrors, UnknownNestedKeyNamesTheKeyPath) {
  const std::string message = error_of(with_material("      poisson_ration: 0.45\n"));
  expect_contains(message, {"test.yaml:9:7: bodies[0].material.poisson_ration: unknown key",
                            "did you mean 'poisson_ratio'?",
                            "youngs_modulus_pa, poisson_ratio, density_kg_per_m3"});
}

TEST(SceneErrors, GlotticViewNeedsItsKeysAUnitNormalAndATool) {
  const std::string section =
      "glottic_view:\n"
      "  opening_centre_m: [-0.06, -0.03, 0]\n"
      "  opening_normal: [0, 0.9, 0]\n"
      "  eye_in_tool_m: [0.3, 0.05, 0]\n";
  expect_contains(
      error_of(std::string(kMinimalScene) + section),
      {"glottic_view.opening_radius_m: missing required key 'opening_radius_m'",
       "test.yaml:24:19: glottic_view.opening_normal: the normal must have unit length"});
  expect_contains(error_of(std::string(kMinimalScene) + section + "  opening_radius_m: 0.004\n" +
                           "  rate_hz: 0\n"),
                  {"glottic_view.rate_hz: value 0 is out of range; valid: (0, 100]"});
  const std::string no_tool =
      replaced("  - name: blade\n    role: tool\n    mesh: blade.obj\n    unit: mm\n", "") +
      "glottic_view:\n  opening_centre_m: [-0.06, -0.03, 0]\n  opening_normal: [0, 1, 0]\n"
      "  opening_radius_m: 0.004\n  eye_in_tool_m: [0.3, 0.05, 0]\n";
  const std::string message = error_of(no_tool);
  expect_contains(message, {"glottic_view: the eye rides on the tool: the scene has no tool"});
}

TEST(SceneErrors, AnEllipticOpeningNeedsBothKeysAnAxisInItsPlaneAndTheSmallerRadiusAcross) {
  const std::string section =
      "glottic_view:\n  opening_centre_m: [-0.06, -0.03, 0]\n  opening_normal: [0, 1, 0]\n"
      "  opening_radius_m: 0.003\n  eye_in_tool_m: [0.3, 0.05, 0]\n";
  expect_contains(
      error_of(std::string(kMinimalScene) + section + "  opening_minor_radius_m: 0.001\n"),
      {"glottic_view.opening_minor_radius_m: an elliptic opening needs both"});
  expect_contains(
      error_of(std::string(kMinimalScene) + section +
               "  opening_major_axis: [0, 1, 0]\n  opening_minor_radius_m: 0.004\n"),
      {"glottic_view.opening_major_axis: the major axis must have unit length and lie in the "
       "opening's plane",
       "glottic_view.opening_minor_radius_m: the minor radius must not exceed opening_radius_m"});
  const auto scene = parse(std::string(kMinimalScene) + section +
                           "  opening_major_axis: [1, 0, 0]\n  opening_minor_radius_m: 0.001\n");
  EXPECT_DOUBLE_EQ(scene->glottic_view->opening_minor_radius_m, 0.001);
  EXPECT_DOUBLE_EQ(scene->glottic_view->opening_major_axis.x(), 1.0);
}

TEST(SceneErrors, GlotticViewLoads) {
  const auto scene = parse(std::string(kMinimalScene) +
                           "glottic_view:\n  opening_centre_m: [-0.06, -0.03, 0]\n"
                           "  opening_normal: [0, 1, 0]\n  opening_radius_m: 0.004\n"
                           "  eye_in_tool_m: [0.3, 0.05, 0]\n");
  ASSERT_TRUE(scene->glottic_view.has_value());
  EXPECT_DOUBLE_EQ(scene->glottic_view->opening_radius_m, 0.004);
  EXPECT_DOUBLE_EQ(scene->glottic_view->eye_in_tool_m.y(), 0.05);
  EXPECT_DOUBLE_EQ(scene->glottic_view->rate_hz, 10.0);
  EXPECT_FALSE(parse(kMinimalScene)->glottic_view.has_value());
}

TEST(SceneErrors, UnrelatedUnknownKeyGetsNoSuggestion) {
  const std::string message = error_of(replaced("  backend: simulated", "  colour: blue"));
  expect_contains(message, {"device.colour: unknown key 'colour'. Valid keys here: backend"});
  EXPECT_EQ(message.find("did you mean"), std::string::npos) << message;
}

TEST(SceneErrors, MissingRequiredKeys) {
  expect_contains(error_of(replaced("name: minimal\n", "")),
                  {"test.yaml:1:1: name: missing required key 'name'"});
  expect_contains(error_of(replaced("    unit: cm\n", "")),
                  {"test.yaml:12:5: bodies[2].unit: missing required key 'unit'"});
  expect_contains(error_of("format_version: 1\nname: x\n"),
                  {"test.yaml:1:1: bodies: missing required key 'bodies'"});
}

TEST(SceneErrors, WrongTypes) {
  expect_contains(error_of(with_material("      youngs_modulus_pa: soft\n")),
                  {"test.yaml:9:26: bodies[0].material.youngs_modulus_pa: expected a finite "
                   "number, got 'soft'"});
  expect_contains(error_of(with_material("      youngs_modulus_pa: \"10000\"\n")),
                  {"bodies[0].material.youngs_modulus_pa: expected a number, got the quoted "
                   "text \"10000\""});
  expect_contains(error_of(std::string(kMinimalScene) + "gravity_mps2: [0, -9.81]\n"),
                  {"test.yaml:22:15: gravity_mps2: expected a sequence of 3 numbers [x, y, z], "
                   "got a sequence of 2"});
  expect_contains(error_of(replaced("  backend: simulated", "  motion_scale: [1]")),
                  {"device.motion_scale: expected a number, got a sequence"});
  expect_contains(error_of(std::string(kMinimalScene) + "run:\n  spin_wait: yes please\n"),
                  {"run.spin_wait: expected true or false, got 'yes please'"});
  expect_contains(error_of("- just\n- a list\n"),
                  {"test.yaml:1:1: (top level): expected a mapping"});
}

TEST(SceneErrors, OutOfRangeValuesStateTheValidRange) {
  expect_contains(error_of(with_material("      youngs_modulus_pa: -5\n")),
                  {"bodies[0].material.youngs_modulus_pa: value -5 is out of range; valid: "
                   "(0, 1e+12]"});
  expect_contains(error_of(with_material("      poisson_ratio: 0.5\n")),
                  {"test.yaml:9:22: bodies[0].material.poisson_ratio: value 0.5 is out of "
                   "range; valid: (-1, 0.5)"});
  expect_contains(error_of(with_material("      poisson_ratio: -1\n")),
                  {"bodies[0].material.poisson_ratio: value -1 is out of range"});
  expect_contains(error_of(with_material("      yeoh_c20_over_c10: -0.47\n")),
                  {"test.yaml:9:26: bodies[0].material.yeoh_c20_over_c10: value -0.47 is out of "
                   "range; valid: [0, 100]"});
  expect_contains(error_of(std::string(kMinimalScene) + "rates:\n  fem_hz: 0\n"),
                  {"test.yaml:23:11: rates.fem_hz: value 0 is out of range; valid: (0, 10000]"});
  expect_contains(error_of(std::string(kMinimalScene) + "rates:\n  haptic_hz: -1000\n"),
                  {"rates.haptic_hz: value -1000 is out of range"});
  expect_contains(error_of(std::string(kMinimalScene) + "dds:\n  domain_id: 300\n"),
                  {"dds.domain_id: value 300 is out of range; valid: [0, 230]"});
  expect_contains(error_of(std::string(kMinimalScene) + "dds:\n  domain_id: 1.5\n"),
                  {"dds.domain_id: expected an integer, got '1.5'"});
}

TEST(SceneErrors, UnknownEnumerationValuesListTheValidOnes) {
  expect_contains(error_of(replaced("unit: cm", "unit: inch")),
                  {"test.yaml:15:11: bodies[2].unit: 'inch' is not one of: m, cm, mm"});
  expect_contains(error_of(replaced("role: obstacle", "role: wall")),
                  {"bodies[2].role: 'wall' is not one of: deformable, tool, obstacle"});
  expect_contains(error_of(replaced("backend: simulated", "backend: phantom")),
                  {"device.backend: 'phantom' is not one of: simulated, replay, remote, "
                   "openhaptics"});
  expect_contains(error_of(with_material("      model: neo_hookean\n")),
                  {"test.yaml:9:14: bodies[0].material.model: 'neo_hookean' is not one of: "
                   "corotational, stable_neo_hookean"});
  expect_contains(error_of(std::string(kMinimalScene) + "solver:\n  compliance_columns: rows\n"),
                  {"solver.compliance_columns: 'rows' is not one of: blocks, normals"});
  expect_contains(error_of(std::string(kMinimalScene) + "contact:\n  held_proxy: back_off\n"),
                  {"contact.held_proxy: 'back_off' is not one of: load, stay"});
  expect_contains(error_of(std::string(kMinimalScene) + "solver:\n  volume_floor_ratio: 1.2\n"),
                  {"solver.volume_floor_ratio: value 1.2 is out of range; valid: [0, 0.9]"});
}

TEST(SceneErrors, TwoTools) {
  expect_contains(error_of(replaced("role: obstacle", "role: tool")),
                  {"test.yaml:13:11: bodies[2].role: a second tool ('palate' after 'blade')"});
}

TEST(SceneErrors, DuplicateNamesAndIds) {
  expect_contains(error_of(replaced("name: jaw", "name: palate")),
                  {"test.yaml:16:11: bodies[3].name: duplicate body name 'palate' (also "
                   "bodies[2])"});
  // Body 3 defaults to id 3; giving body 0 id 3 collides with it.
  expect_contains(error_of(replaced("    role: deformable", "    id: 3\n    role: deformable")),
                  {"bodies[2].id: duplicate body id 3 (also bodies[0]"});
}

TEST(SceneErrors, DuplicateKey) {
  expect_contains(error_of(replaced("    unit: mm\n", "    unit: mm\n    unit: m\n")),
                  {"test.yaml:8:5: bodies[0].unit: duplicate key (first given on line 7)"});
}

TEST(SceneErrors, DeviceToolReferences) {
  expect_contains(error_of(replaced("  backend: simulated", "  tool: miller1")),
                  {"test.yaml:21:9: device.tool: no body named 'miller1'; bodies: tongue, "
                   "blade, palate, jaw"});
  expect_contains(error_of(replaced("  backend: simulated", "  tool: palate")),
                  {"device.tool: body 'palate' is a obstacle, not a tool"});
  expect_contains(error_of(replaced("role: tool", "role: obstacle")),
                  {"test.yaml:21:3: device: a device drives a tool, but no body has role: tool"});
}

TEST(SceneErrors, RoleSpecificKeys) {
  expect_contains(
      error_of(
          replaced("    unit: cm\n", "    unit: cm\n    material:\n      poisson_ratio: 0.3\n")),
      {"test.yaml:16:5: bodies[2].material: 'material' is not valid here: only deformable "
       "bodies have it (this body is a obstacle)"});
  expect_contains(error_of(replaced("mesh: palate.obj", "mesh: palate.node")),
                  {"bodies[2].mesh: a rigid body needs a surface mesh (.obj, .stl, .ply), got "
                   "'palate.node'"});
  expect_contains(error_of(replaced("mesh: tongue.node", "mesh: tongue.obj")),
                  {"bodies[0].mesh: a deformable body needs a tetrahedral mesh (.node, .msh, "
                   ".vtk)"});
}

TEST(SceneErrors, MissingMeshFilesWhenChecked) {
  TempDir dir;
  const std::string message = [&] {
    try {
      parse_scene(kMinimalScene, "test.yaml", dir.path());
    } catch (const SceneError& error) {
      return std::string(error.what());
    }
    return std::string();
  }();
  expect_contains(message, {"test.yaml:6:11: bodies[0].mesh: mesh file not found: " +
                                (dir.path() / "tongue.node").string(),
                            "bodies[0].mesh: TetGen element file not found: " +
                                (dir.path() / "tongue.ele").string(),
                            "test.yaml:18:11: bodies[3].mesh: mesh file not found"});
}

TEST(SceneErrors, ContactPairDeclarations) {
  const std::string base = std::string(kMinimalScene) + "contact:\n  include_pairs:\n";
  expect_contains(error_of(base + "    - [palate, jaw]\n"),
                  {"contact.include_pairs: [palate, jaw]: only deformable/obstacle pairs can be "
                   "declared in contact (obstacles never move)"});
  expect_contains(error_of(base + "    - [tongue, teeth]\n"),
                  {"test.yaml:24:16: contact.include_pairs[0][1]: no body named 'teeth'"});
  expect_contains(error_of(base + "    - [tongue, palate]\n  exclude_pairs: [[palate, tongue]]\n"),
                  {"contact.exclude_pairs: pair [tongue, palate] is both included and "
                   "excluded"});
}

TEST(SceneErrors, LockstepPeriodsMustBeWholeMultiples) {
  expect_contains(
      error_of(std::string(kMinimalScene) +
               "rates:\n  fem_hz: 300\nrun:\n  mode: lockstep\n  base_period_ms: 1\n"),
      {"run.base_period_ms: in lockstep the period of rates.fem_hz (3333333 ns) must be a whole "
       "multiple of the base period (1000000 ns)"});
  expect_contains(error_of(std::string(kMinimalScene) + "run:\n  base_period_ms: 1\n"),
                  {"run.base_period_ms: 'base_period_ms' is not valid here: it applies to mode: "
                   "lockstep only"});
}

TEST(SceneErrors, DeviceBackEndSettings) {
  expect_contains(error_of(replaced("backend: simulated", "backend: replay")),
                  {"device.replay_file: missing required key 'replay_file'"});
  expect_contains(error_of(replaced("backend: simulated", "backend: simulated\n  model: custom")),
                  {"device.limits: model 'custom' needs every limit"});
  expect_contains(
      error_of(replaced("backend: simulated",
                        "limits:\n    peak_force_n: 2\n    continuous_force_n: 3")),
      {"device.limits.continuous_force_n: the continuous force cannot exceed the peak force"});
}

TEST(SceneErrors, PoseErrors) {
  expect_contains(
      error_of(
          replaced("unit: m\n", "unit: m\n    pose:\n      orientation_quat_wxyz: [2, 0, 0, 0]\n")),
      {"bodies[3].pose.orientation_quat_wxyz[0]: value 2 is out of range"});
  expect_contains(
      error_of(replaced("unit: m\n",
                        "unit: m\n    pose:\n      orientation_quat_wxyz: [0.5, 0.5, 0, 0]\n")),
      {"bodies[3].pose.orientation_quat_wxyz: not a unit quaternion"});
  expect_contains(error_of(replaced("unit: m\n",
                                    "unit: m\n    pose:\n      orientation_rpy_deg: "
                                    "[0, 0, 0]\n      orientation_quat_wxyz: [1, "
                                    "0, 0, 0]\n")),
                  {"give one orientation, not both"});
}

TEST(SceneErrors, UnknownQosTopicAndVersion) {
  expect_contains(error_of(std::string(kMinimalScene) + "qos:\n  DevicePoses: {deadline_ms: 2}\n"),
                  {"test.yaml:23:3: qos.DevicePoses: unknown key 'DevicePoses'; did you mean "
                   "'DevicePose'? Valid keys here: DevicePose, ForceCommand, ContactSet"});
  expect_contains(error_of(std::string(kMinimalScene) + "qos:\n  SimClock: {durability: x}\n"),
                  {"qos.SimClock.durability: unknown key 'durability'. Valid keys here: "
                   "deadline_ms, history_depth, reliability"});
  expect_contains(error_of(replaced("format_version: 1", "format_version: 2")),
                  {"test.yaml:1:17: format_version: value 2 is out of range; valid: [1, 1]"});
}

TEST(SceneErrors, YamlSyntaxErrorNamesTheLine) {
  expect_contains(error_of("format_version: 1\nname: [unclosed\n"),
                  {"test.yaml:3:1: YAML syntax error"});
}

TEST(SceneErrors, SeveralErrorsAreCollected) {
  std::string text = with_material("      poisson_ratio: 0.7\n");
  text += "rates:\n  fem_hz: -1\n";
  const std::string message = error_of(text);
  expect_contains(message,
                  {"2 problems in the scene:", "bodies[0].material.poisson_ratio", "rates.fem_hz"});
}

TEST(SceneErrors, SceneErrorCarriesStructuredIssues) {
  try {
    parse(with_material("      poisson_ratio: 0.7\n"));
    FAIL() << "expected a SceneError";
  } catch (const SceneError& error) {
    ASSERT_EQ(error.issues().size(), 1u);
    const SceneIssue& issue = error.issues().front();
    EXPECT_EQ(issue.file, "test.yaml");
    EXPECT_EQ(issue.line, 9);
    EXPECT_EQ(issue.column, 22);
    EXPECT_EQ(issue.key_path, "bodies[0].material.poisson_ratio");
  }
}

TEST(SceneErrors, LoadSceneNamesAMissingFile) {
  try {
    load_scene("/nonexistent/scene.yaml");
    FAIL() << "expected a SceneError";
  } catch (const SceneError& error) {
    EXPECT_STREQ(error.what(), "/nonexistent/scene.yaml: cannot open the scene file");
  }
}

}  // namespace
}  // namespace fahr::scene::test
