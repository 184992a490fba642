// The ArtiSynth tongue (11,098 tets, real anatomy) steps stably under
// gravity with its lowest 10 mm fixed.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <functional>

#include "scenes.h"
#include "tetgen.h"

namespace fahr::fem {
namespace {

std::string tongue_stem() {
  return std::string(FAHR_TONGUE_DIR) + "/tongue.1";
}

// The lowest 10 mm (+y up) are fixed.
std::vector<std::uint32_t> tongue_base(const BodyMesh& mesh) {
  double lowest = 1e9;
  for (const auto& p : mesh.nodes_m) lowest = std::min(lowest, p.y());
  return test::nodes_where(mesh, [&](const Eigen::Vector3d& p) { return p.y() < lowest + 0.010; });
}

TEST(Tongue, StepsStablyUnderGravity) {
  const std::string stem = tongue_stem();
  ASSERT_TRUE(std::filesystem::exists(stem + ".node"))
      << "ArtiSynth tongue not found at " << stem
      << ".node: ../shared/meshes/artisynth-tongue must be beside the checkout";
  BodyMesh mesh;
  std::string error;
  ASSERT_TRUE(test::read_tetgen(stem, mesh, error)) << error;
  ASSERT_EQ(mesh.tets.size(), 11098u);
  const auto fixed = tongue_base(mesh);
  BodySettings settings;  // neonatal tongue material, +y up, gravity -y
  settings.time_step = std::chrono::milliseconds(10);
  // Lagged factorisation, refreshed when an element turns by 0.1 rad.
  settings.solver.refactor_period = 0;
  settings.sleep.enabled = false;
  auto made = Body::create(settings, mesh.nodes_m, mesh.tets, fixed);
  ASSERT_EQ(made.error, "");
  Body& body = *made.body;
  double largest_speed = 0.0;
  int refactorisations = 0;
  for (int k = 0; k < 150; ++k) {
    const StepReport report = body.step();
    refactorisations += report.refactorised ? 1 : 0;
    ASSERT_FALSE(report.solve_failed);
    ASSERT_TRUE(test::all_finite(body)) << "step " << k;
    EXPECT_EQ(report.inverted_elements, 0);
    if (k >= 100) {
      for (const double v : body.velocities_m_per_s())
        largest_speed = std::max(largest_speed, std::abs(v));
    }
  }
  // Linear FEM sags 3.14 mm at E = 10 kPa (dependency-facts.md); at 7.74 kPa
  // about 4 mm. The corotated sag must be of that order, and settling.
  const double sag = test::max_displacement(body);
  std::printf(
      "[ info ] tongue: %zu fixed nodes, max displacement after 1.5 s %.3f mm, speed %.3f mm/s, "
      "%d refactorisations in 150 steps\n",
      fixed.size(), 1e3 * sag, 1e3 * largest_speed, refactorisations);
  EXPECT_GT(sag, 1e-3);
  EXPECT_LT(sag, 2e-2);
}

TEST(Tongue, PressedByALaryngoscopeAndReleased) {
  // Eight tool contacts on the top of the tongue are pushed 10 mm down in
  // 0.5 s (a blade pressing), held, then the contact set stops (the trainee
  // lifts the blade). The lagged direct solve must stay finite and
  // uninverted, refactorise on rotation, and let the tongue spring back.
  const std::string stem = tongue_stem();
  ASSERT_TRUE(std::filesystem::exists(stem + ".node"))
      << "ArtiSynth tongue not found at " << stem
      << ".node: ../shared/meshes/artisynth-tongue must be beside the checkout";
  BodyMesh mesh;
  std::string error;
  ASSERT_TRUE(test::read_tetgen(stem, mesh, error)) << error;
  BodySettings settings;
  settings.time_step = std::chrono::milliseconds(10);
  settings.solver.refactor_period = 0;  // refactorise on 0.1 rad of rotation
  settings.sleep.enabled = false;
  auto made = Body::create(settings, mesh.nodes_m, mesh.tets, tongue_base(mesh));
  ASSERT_EQ(made.error, "");
  Body& body = *made.body;
  // Eight spheres along the top of the tongue, each tied to the nodes
  // within 6 mm of a top node, as an AIST sphere spreads over the tets it
  // overlaps. Weights proportional to nodal mass: then the contract's spread
  // (w_i / m_i) dc / sum_j (w_j^2 / m_j) moves every linked node by exactly
  // dc. With uniform weights the lightest node takes nearly all of it (on
  // this mesh a 0.2 mm press moved one node 5.8 mm and inverted elements).
  std::vector<std::pair<double, std::uint32_t>> heights;
  for (std::uint32_t i = 0; i < mesh.nodes_m.size(); ++i)
    heights.emplace_back(mesh.nodes_m[i].y(), i);
  std::sort(heights.begin(), heights.end(), std::greater<>());
  std::vector<std::uint32_t> centres;
  for (const auto& [y, node] : heights) {
    const Eigen::Vector3d& at = mesh.nodes_m[node];  // clang before 16 cannot capture `node`
    const bool apart = std::all_of(centres.begin(), centres.end(), [&](std::uint32_t c) {
      return (mesh.nodes_m[c] - at).norm() > 0.008;
    });
    if (apart) centres.push_back(node);
    if (centres.size() == 8) break;
  }
  SphereLinks links;
  ContactSet set;
  for (std::size_t s = 0; s < centres.size(); ++s) {
    const auto near = test::nodes_where(mesh, [&](const Eigen::Vector3d& p) {
      return (p - mesh.nodes_m[centres[s]]).norm() < 0.006;
    });
    std::vector<double> w;
    w.reserve(near.size());
    double mass = 0.0;
    for (const std::uint32_t n : near) mass += body.mass_kg()[n];
    for (const std::uint32_t n : near) w.push_back(body.mass_kg()[n] / mass);
    ASSERT_EQ(links.add_sphere(near, w, 0.002), "");
    Contact contact;
    contact.sphere_id = static_cast<std::uint32_t>(s);
    contact.state = ContactState::kActive;
    contact.normal = -Eigen::Vector3d::UnitY();  // the tool presses from above
    set.contacts.push_back(contact);
  }
  std::vector<Eigen::Vector3d> start;
  for (std::uint32_t s = 0; s < 8; ++s) start.push_back(links.centre(s, body.positions_m().data()));
  int refactorisations = 0;
  int inverted_while_pressed = 0;
  for (int k = 0; k < 100; ++k) {
    const double depth = 0.010 * std::min(1.0, (k + 1) / 50.0);
    // (c - q) . n >= r: each centre at least `depth` below where it started.
    for (std::uint32_t s = 0; s < 8; ++s)
      set.contacts[s].plane_point_m = start[s] - Eigen::Vector3d(0, depth - links.radius_m(s), 0);
    set.state_step = body.step_index();
    const StepReport report = body.step(&set, &links);
    refactorisations += report.refactorised ? 1 : 0;
    ASSERT_TRUE(test::all_finite(body)) << "step " << k;
    inverted_while_pressed = std::max(inverted_while_pressed, report.inverted_elements);
  }
  for (std::uint32_t s = 0; s < 8; ++s) {
    // One-sided: pressed at least 10 mm down (the tongue may sag further).
    const double pressed_to = start[s].y() - 0.010;
    EXPECT_LE(links.centre(s, body.positions_m().data()).y(), pressed_to + 1e-6);
  }
  const double pressed = test::max_displacement(body);
  StepReport last;
  for (int k = 0; k < 150; ++k) {
    last = body.step();
    refactorisations += last.refactorised ? 1 : 0;
    ASSERT_TRUE(test::all_finite(body)) << "release step " << k;
  }
  const double released = test::max_displacement(body);
  std::printf(
      "[ info ] tongue pressed 10 mm: max displacement %.2f mm (at most %d elements inverted), 1.5 "
      "s "
      "after release %.2f mm, %d refactorisations in 250 steps\n",
      1e3 * pressed, inverted_while_pressed, 1e3 * released, refactorisations);
  EXPECT_EQ(last.inverted_elements, 0);
  EXPECT_GT(pressed, 0.009);
  EXPECT_LT(released, 0.008);  // back near its gravity sag (about 5 mm)
  EXPECT_GT(refactorisations, 0);
}

}  // namespace
}  // namespace fahr::fem
