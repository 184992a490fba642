// fem::ContactStep: the free-motion centres are the motion without this
// step's contact forces, W is reused only while it is still exact, a reset
// body steps as a new one, and a step allocates nothing once sized.
#include "fahr/fem/contact_step.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#ifndef FAHR_SANITIZE_BUILD
#include "allocation_counter.h"
#include "suitesparse_allocations.h"
#endif
#include "scenes.h"

namespace fahr::fem {
namespace {

// The bar's free-end top nodes, one sphere each (weight 1).
struct Bar {
  BodyMesh mesh = test::bar_mesh(2);
  std::vector<std::uint32_t> top;
  SphereLinks links;
  Bar() {
    top = test::nodes_where(
        mesh, [](const Eigen::Vector3d& p) { return p.x() > 0.029 && p.y() > 0.0099; });
    const double w = 1.0;
    for (const std::uint32_t n : top) EXPECT_EQ(links.add_sphere({&n, 1}, {&w, 1}, 0.001), "");
  }
};

BodySettings rest_factor_settings() {
  BodySettings s;
  s.sleep.enabled = false;
  s.gravity_m_per_s2 = Eigen::Vector3d::Zero();
  s.solver.refactor_period = 0;
  s.solver.refactor_rotation_rad = 0.0;  // one factorisation: W exact throughout
  return s;
}

// A bar body with the settings above (every test that compares two steps
// makes two).
std::unique_ptr<Body> bar_body(const Bar& bar) {
  return test::make_body(rest_factor_settings(), bar.mesh, test::fixed_x0(bar.mesh));
}

// A tool pressing the first sphere down with 0.01 N, active on its plane.
ContactSet press(const Bar& bar, const Body& body, double force_n) {
  ContactSet set;
  set.state_step = body.step_index();
  for (std::size_t s = 0; s < bar.top.size(); ++s) {
    Contact c;
    c.sphere_id = static_cast<std::uint32_t>(s);
    c.normal = Eigen::Vector3d(0, -1, 0);
    c.state = s == 0 ? ContactState::kActive : ContactState::kCandidate;
    c.force_n = s == 0 ? force_n : 0.0;
    c.plane_point_m = body.position(bar.top[s]) + Eigen::Vector3d(0, 0.0015, 0);
    set.contacts.push_back(c);
  }
  return set;
}

// The same set with every contact a candidate: no force, no projection.
ContactSet as_candidates(ContactSet set) {
  for (Contact& c : set.contacts) c.state = ContactState::kCandidate;
  return set;
}

TEST(ContactStep, FreeCentresAreTheMotionWithoutTheContactForces) {
  Bar bar;
  auto pushed = bar_body(bar);
  auto free = bar_body(bar);
  ASSERT_TRUE(pushed && free);
  ContactStep with(*pushed, bar.links);
  ContactStepSettings no_forces;
  no_forces.apply_contact_forces = false;
  ContactStep without(*free, bar.links, no_forces);
  ContactSet set = press(bar, *pushed, 0.01);
  // Candidates only on the second body: no projection, no force.
  const ContactSet candidates = as_candidates(set);
  with.step(&set);
  without.step(&candidates);
  ASSERT_EQ(with.compliance_spheres().size(), bar.top.size());
  for (std::size_t s = 0; s < bar.top.size(); ++s) {
    const Eigen::Vector3d expected = free->position(bar.top[s]);
    EXPECT_LT((with.free_centres()[s] - expected).norm(), 1e-9) << "sphere " << s;
  }
  // And the force did move the pushed sphere down: the check is not vacuous.
  EXPECT_LT(with.free_positions_m()[3 * bar.top[0] + 1], free->position(bar.top[0]).y() - 1e-7);
}

TEST(ContactStep, AlongNormalsGivesTheSameFreeCentresAndTheBlocksAlongTheSetsNormals) {
  // W along the set's normals (one column a sphere) carries the same
  // free-motion centres as the 3x3 blocks, and its columns are the blocks
  // times those normals; a turned normal is solved again, not reused.
  Bar bar;
  auto blocks_body = bar_body(bar);
  auto along_body = bar_body(bar);
  ASSERT_TRUE(blocks_body && along_body);
  ContactStep blocks(*blocks_body, bar.links);
  ContactStepSettings along_settings;
  along_settings.compliance_along_normals = true;
  ContactStep along(*along_body, bar.links, along_settings);
  ContactSet set = press(bar, *blocks_body, 0.01);
  set.contacts[1].normal = Eigen::Vector3d(0.0, -0.6, 0.8);
  blocks.step(&set);
  along.step(&set);
  const std::size_t k = bar.top.size();
  ASSERT_EQ(along.compliance_spheres().size(), k);
  ASSERT_EQ(along.compliance().size(), 3 * k * k);
  ASSERT_EQ(along.compliance_normals().size(), k);
  EXPECT_TRUE(blocks.compliance_normals().empty());
  for (std::size_t s = 0; s < k; ++s) {
    EXPECT_LT((along.free_centres()[s] - blocks.free_centres()[s]).norm(), 1e-12) << "sphere " << s;
    for (std::size_t t = 0; t < k; ++t) {
      const Eigen::Vector3d n = set.contacts[t].normal;
      EXPECT_EQ(along.compliance_normals()[t], n);
      for (std::size_t d = 0; d < 3; ++d) {
        double expected = 0.0;
        for (std::size_t e = 0; e < 3; ++e) {
          expected += double{blocks.compliance()[(3 * s + d) * 3 * k + 3 * t + e]} *
                      n[static_cast<Eigen::Index>(e)];
        }
        EXPECT_NEAR(along.compliance()[(3 * s + d) * k + t], expected,
                    1e-6 * std::abs(blocks.compliance()[0]));
      }
    }
  }
  // The pushed sphere's free centre differs from where it went: not vacuous.
  EXPECT_GT(
      (along.free_centres()[0] - bar.links.centre(0, along_body->positions_m().data())).norm(),
      1e-7);
  along.step(&set);
  EXPECT_EQ(along.compliance_reuses(), 1u);
  set.contacts[2].normal = Eigen::Vector3d(1.0, 0.0, 0.0);
  along.step(&set);
  EXPECT_EQ(along.compliance_solves(), 2u);
}

TEST(ContactStep, APenetratingSphereIsCorrectedThroughTheTissueNotItsOwnNodesAlone) {
  // The tool's plane 0.5 mm into sphere 0 (its one node), no force: the
  // step meets the constraint with an impulse on the tissue, which moves
  // the neighbouring top nodes as W says. Algorithm 1's projection alone
  // would move only sphere 0's node and leave them where the free step put
  // them.
  Bar bar;
  auto pressed = bar_body(bar);
  auto free = bar_body(bar);
  ASSERT_TRUE(pressed && free);
  ContactStep step(*pressed, bar.links);
  ContactStep free_step(*free, bar.links);
  ContactSet set = press(bar, *pressed, 0.0);
  set.contacts[0].plane_point_m = pressed->position(bar.top[0]) + Eigen::Vector3d(0, 0.0005, 0);
  const ContactSet candidates = as_candidates(set);
  step.step(&set);
  free_step.step(&candidates);
  const std::size_t k = bar.top.size();
  ASSERT_EQ(step.compliance_spheres().size(), k);
  // Sphere 0 on its plane: radius 1 mm, plane 0.5 mm above its rest centre.
  const double gap =
      (bar.links.centre(0, pressed->positions_m().data()) - set.contacts[0].plane_point_m)
          .dot(set.contacts[0].normal) -
      bar.links.radius_m(0);
  EXPECT_GT(gap, -1e-6);
  // The impulse W_00 found (along -y), and what W_s0 says of each other
  // sphere's motion under it.
  const auto w = [&](std::size_t s, std::size_t t) {
    return double{step.compliance()[(3 * s + 1) * 3 * k + 3 * t + 1]};
  };
  const double moved0 = free->position(bar.top[0]).y() - pressed->position(bar.top[0]).y();
  ASSERT_GT(moved0, 4e-4);
  const double impulse = moved0 / w(0, 0);
  double largest = 0.0;
  for (std::size_t s = 1; s < k; ++s) {
    const double moved = free->position(bar.top[s]).y() - pressed->position(bar.top[s]).y();
    EXPECT_NEAR(moved, w(s, 0) * impulse, 0.02 * moved0) << "sphere " << s;
    largest = std::max(largest, moved);
  }
  EXPECT_GT(largest, 0.1 * moved0);
}

TEST(ContactStep, ADivergedStepResetsTheBodyToRest) {
  // A force no tissue takes (1e9 N on one sphere, force only) throws the
  // bar's tip kilometres: with a divergence limit the step resets the body
  // to rest and says so; without one the body is left where it went.
  Bar bar;
  ContactSet set;
  Contact c;
  c.sphere_id = 0;
  c.kind = ContactKind::kForceOnly;
  c.state = ContactState::kActive;
  c.normal = Eigen::Vector3d(0, -1, 0);
  c.force_n = 1e9;
  set.contacts.push_back(c);
  auto unchecked_body = bar_body(bar);
  auto checked_body = bar_body(bar);
  ASSERT_TRUE(unchecked_body && checked_body);
  ContactStep unchecked(*unchecked_body, bar.links);
  ContactStepSettings limit;
  limit.divergence_limit_m = 0.1;
  ContactStep checked(*checked_body, bar.links, limit);
  set.state_step = unchecked_body->step_index();
  const StepReport far = unchecked.step(&set);
  EXPECT_FALSE(far.diverged_reset);
  EXPECT_GT(
      (unchecked_body->position(bar.top[0]) - unchecked_body->rest_position(bar.top[0])).norm(),
      0.1);
  const StepReport reset = checked.step(&set);
  EXPECT_TRUE(reset.diverged_reset);
  for (std::uint32_t n = 0; n < checked_body->node_count(); ++n) {
    EXPECT_EQ(checked_body->position(n), checked_body->rest_position(n)) << "node " << n;
  }
  // And the next step, without the force, is an ordinary one.
  const StepReport next = checked.step(nullptr);
  EXPECT_FALSE(next.diverged_reset);
  EXPECT_TRUE(checked_body->positions_m()[0] == checked_body->positions_m()[0]);
}

TEST(ContactStep, TheToolReactionOfABarRestingOnTheToolIsItsWeight) {
  // A bar fixed nowhere lies under gravity on the tool: one active contact
  // per bottom node, the plane at the bottom face. Only the tool holds it,
  // so once it has settled the reaction the FEM reports (applied forces plus
  // the projection's moves over h^2) is the bar's weight, a figure the tool
  // rows do not carry (0.2 % short of it here: the mass-proportional damping
  // acts on each step's free fall). Tried on the rest factor alone, the free
  // bar diverged, so it steps with the default refactorisation.
  const BodyMesh mesh = test::bar_mesh(2);
  BodySettings settings;
  settings.sleep.enabled = false;
  const Eigen::Vector3d g(0.0, -9.81, 0.0);
  settings.gravity_m_per_s2 = g;
  auto body = test::make_body(settings, mesh, {});
  ASSERT_TRUE(body);
  const std::vector<std::uint32_t> bottom =
      test::nodes_where(mesh, [](const Eigen::Vector3d& p) { return p.y() < 1e-9; });
  SphereLinks links;
  const double w = 1.0;
  const double radius = 0.001;
  for (const std::uint32_t n : bottom) EXPECT_EQ(links.add_sphere({&n, 1}, {&w, 1}, radius), "");
  ContactSet set;
  for (std::size_t s = 0; s < bottom.size(); ++s) {
    Contact c;
    c.sphere_id = static_cast<std::uint32_t>(s);
    c.normal = Eigen::Vector3d(0, 1, 0);
    c.state = ContactState::kActive;
    c.plane_point_m =
        Eigen::Vector3d(body->position(bottom[s]).x(), -radius, body->position(bottom[s]).z());
    set.contacts.push_back(c);
  }
  ContactStep step(*body, links);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  constexpr int kSteps = 600;
  constexpr int kAveraged = 100;
  for (int k = 0; k < kSteps; ++k) {
    set.state_step = body->step_index();
    step.step(&set);
    if (k >= kSteps - kAveraged) mean += step.tool_reaction_n() / kAveraged;
  }
  const Eigen::Vector3d weight = -body->total_mass_kg() * g;
  EXPECT_NEAR(mean.y(), weight.y(), 0.01 * weight.y());
  EXPECT_LT(std::hypot(mean.x(), mean.z()), 0.01 * weight.y());
  // And the bar rests on the tool: it did not sink through, nor fly off.
  EXPECT_GT(test::lowest_free_node_height(*body), -1e-6);
  EXPECT_LT(test::lowest_free_node_height(*body), 1e-6);
}

TEST(ContactStep, ReusesComplianceOnlyWhileSpheresAndFactorAreUnchanged) {
  Bar bar;
  auto body = bar_body(bar);
  ASSERT_TRUE(body);
  ContactStep step(*body, bar.links);
  ContactSet set = press(bar, *body, 0.0);
  step.step(&set);
  step.step(&set);
  EXPECT_EQ(step.compliance_solves(), 1u);
  EXPECT_EQ(step.compliance_reuses(), 1u);
  set.contacts.pop_back();  // other spheres: solved again
  step.step(&set);
  EXPECT_EQ(step.compliance_solves(), 2u);
  EXPECT_EQ(step.compliance_spheres().size(), bar.top.size() - 1);
}

TEST(ContactStep, AResetBodyStepsAsANewOne) {
  Bar bar;
  BodySettings settings = rest_factor_settings();
  settings.solver.refactor_rotation_rad = 0.1;
  auto used = test::make_body(settings, bar.mesh, test::fixed_x0(bar.mesh));
  auto fresh = test::make_body(settings, bar.mesh, test::fixed_x0(bar.mesh));
  ASSERT_TRUE(used && fresh);
  ContactStep used_step(*used, bar.links);
  ContactStep fresh_step(*fresh, bar.links);
  ASSERT_TRUE(used_step.fix_compliance_spheres(std::vector<std::uint32_t>{0, 1}));
  ASSERT_TRUE(fresh_step.fix_compliance_spheres(std::vector<std::uint32_t>{0, 1}));
  for (int k = 0; k < 30; ++k) {
    ContactSet set = press(bar, *used, 0.5);
    used_step.step(&set);
  }
  ASSERT_TRUE(used->reset_to_rest());
  ASSERT_TRUE(used_step.reset());
  for (int k = 0; k < 10; ++k) {
    ContactSet a = press(bar, *used, 0.02), b = press(bar, *fresh, 0.02);
    used_step.step(&a);
    fresh_step.step(&b);
  }
  for (std::uint32_t n = 0; n < used->node_count(); ++n)
    EXPECT_EQ(used->position(n), fresh->position(n)) << n;
  for (std::size_t i = 0; i < used_step.compliance().size(); ++i) {
    EXPECT_EQ(used_step.compliance()[i], fresh_step.compliance()[i]);
  }
}

#ifndef FAHR_SANITIZE_BUILD
TEST(ContactStep, StepAllocatesNothingOnceSized) {
  test::hook_suitesparse_allocations();
  Bar bar;
  auto body = bar_body(bar);
  ASSERT_TRUE(body);
  // A floor just under the rest volume, so the pressed tets exercise it.
  ContactStepSettings settings;
  settings.volume_floor.ratio = 0.999;
  ContactStep step(*body, bar.links, settings);
  ContactSet set = press(bar, *body, 0.01);
  // The tool 0.5 mm into sphere 0: the pushed sphere touches (a force on a
  // sphere the tool does not touch is taken back by the step).
  set.contacts[0].plane_point_m = body->position(bar.top[0]) + Eigen::Vector3d(0, 0.0005, 0);
  std::vector<double> extra(3 * body->node_count(), 0.0);
  // A point load on the next node crushes its tets below the floor (the
  // correction bends the bar as a whole, which hardly changes a volume).
  extra[3 * bar.top[1] + 1] = -0.2;
  for (int k = 0; k < 3; ++k) step.step(&set, extra);
  fahr::test::AllocationCounter counter;
  int floor_moves = 0;
  for (int k = 0; k < 20; ++k) {
    set.state_step = body->step_index();
    floor_moves += step.step(&set, extra).projection.volume_floor_below;
  }
  const long news = counter.count();
  const long suitesparse_allocs = counter.other_count();
  EXPECT_GT(floor_moves, 0);
  EXPECT_EQ(news, 0);
  EXPECT_EQ(suitesparse_allocs, 0);
}
#endif

}  // namespace
}  // namespace fahr::fem
