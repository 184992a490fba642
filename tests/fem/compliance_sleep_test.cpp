// Compliance blocks against a direct force-response experiment; sleep.
#include <gtest/gtest.h>

#include "scenes.h"

namespace fahr::fem {
namespace {

SphereLinks tip_spheres(const BodyMesh& mesh, std::size_t count) {
  SphereLinks links;
  for (std::size_t s = 0; s < count; ++s) {
    const std::array<double, 4> w = {0.1, 0.2, 0.3, 0.4};
    EXPECT_EQ(links.add_sphere(mesh.tets[mesh.tets.size() - 1 - 5 * s], w, 0.001), "");
  }
  return links;
}

// No gravity, so a body at rest stays there (f = 0), and 10 ms steps.
BodySettings still_settings() {
  BodySettings settings;
  settings.gravity_m_per_s2.setZero();
  settings.time_step = std::chrono::milliseconds(10);
  return settings;
}

// Gravity, 10 ms steps, never asleep, a factorisation every step.
BodySettings sagging_settings(std::size_t spheres, CholmodFactorKind factor) {
  BodySettings settings;
  settings.time_step = std::chrono::milliseconds(10);
  settings.sleep.enabled = false;
  settings.max_compliance_spheres = spheres;
  settings.solver.cholmod.factor = factor;
  return settings;
}

TEST(Compliance, MatchesTheResponseOfOneStep) {
  // At rest without gravity f = 0, so one step with force F on sphere t
  // (spread as J^T F) moves sphere s by exactly W_st F.
  const BodyMesh mesh = test::bar_mesh(2);
  const BodySettings settings = still_settings();
  const SphereLinks links = tip_spheres(mesh, 3);
  const std::vector<std::uint32_t> spheres = {0, 1, 2};
  auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
  ASSERT_NE(body, nullptr);
  std::vector<float> w(81);
  ASSERT_TRUE(body->compliance(spheres, links, w));
  for (int r = 0; r < 9; ++r) {
    EXPECT_GT(w[static_cast<std::size_t>(10 * r)], 0.0f);
    for (int c = 0; c < 9; ++c) {
      EXPECT_NEAR(w[static_cast<std::size_t>(9 * r + c)], w[static_cast<std::size_t>(9 * c + r)],
                  1e-6 * w[0]);
    }
  }
  const Eigen::Vector3d force(0.002, -0.01, 0.004);  // N, on sphere 1
  const auto nodes = links.nodes(1);
  const auto weights = links.weights(1);
  std::vector<Eigen::Vector3d> before;
  for (std::uint32_t s = 0; s < 3; ++s)
    before.push_back(links.centre(s, body->positions_m().data()));
  for (std::size_t m = 0; m < nodes.size(); ++m)
    body->set_external_force(nodes[m], weights[m] * force);
  body->step();
  for (std::uint32_t s = 0; s < 3; ++s) {
    const Eigen::Vector3d moved = links.centre(s, body->positions_m().data()) - before[s];
    Eigen::Vector3d predicted = Eigen::Vector3d::Zero();
    for (std::size_t d = 0; d < 3; ++d) {
      for (std::size_t e = 0; e < 3; ++e) {
        predicted[static_cast<Eigen::Index>(d)] +=
            w[(3 * std::size_t{s} + d) * 9 + 3 + e] * force[static_cast<Eigen::Index>(e)];
      }
    }
    // float storage: 1e-6 relative.
    EXPECT_NEAR((moved - predicted).norm(), 0.0, 1e-6 * moved.norm() + 1e-15) << "sphere " << s;
  }
}

TEST(Compliance, AlongNormalsIsTheBlocksTimesTheNormals) {
  // One column a sphere, W_st n_t, is the 3x3 blocks applied to n_t; the
  // 3x3 blocks' kept columns are not disturbed by it.
  const BodyMesh mesh = test::bar_mesh(2);
  const BodySettings settings = still_settings();
  const SphereLinks links = tip_spheres(mesh, 3);
  const std::vector<std::uint32_t> spheres = {2, 0, 1};
  const std::vector<Eigen::Vector3d> normals = {Eigen::Vector3d(0.0, 0.6, 0.8),
                                                Eigen::Vector3d(-1.0, 0.0, 0.0),
                                                Eigen::Vector3d(0.0, 0.0, 1.0)};
  auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
  ASSERT_NE(body, nullptr);
  std::vector<float> blocks(81), along(27), again(81);
  ASSERT_TRUE(body->compliance(spheres, links, blocks));
  ASSERT_TRUE(body->compliance_along(spheres, normals, links, along));
  ASSERT_TRUE(body->compliance(spheres, links, again));
  EXPECT_EQ(blocks, again);
  double largest = 0.0;
  for (const float v : along) largest = std::max(largest, double{std::abs(v)});
  ASSERT_GT(largest, 0.0);
  for (std::size_t s = 0; s < 3; ++s) {
    for (std::size_t t = 0; t < 3; ++t) {
      for (std::size_t d = 0; d < 3; ++d) {
        double expected = 0.0;
        for (std::size_t e = 0; e < 3; ++e) {
          expected += double{blocks[(3 * s + d) * 9 + 3 * t + e]} *
                      normals[t][static_cast<Eigen::Index>(e)];
        }
        EXPECT_NEAR(along[(3 * s + d) * 3 + t], expected, 1e-6 * largest)
            << s << " " << t << " " << d;
      }
    }
  }
  std::vector<float> short_out(26);
  EXPECT_FALSE(body->compliance_along(spheres, normals, links, short_out));
  EXPECT_FALSE(body->compliance_along(spheres, {normals.data(), 2}, links, along));
}

TEST(Compliance, HalfSolvesOnASupernodalFactorGiveTheBlockOfFullSolves) {
  // W = h^2 (L^-1 P J^T)^T (L^-1 P J^T) on the supernodes each sphere
  // reaches, against W = h^2 J A^-1 J^T from full solves on a simplicial
  // factor of the same A, at rest and after the bar sagged (refactorised),
  // for spheres near the fixed end, at the tip and between, where the
  // reaches share little and much.
  const BodyMesh mesh = test::bar_mesh(3);
  const BodySettings supernodal = sagging_settings(8, CholmodFactorKind::kSupernodal);
  const BodySettings simplicial = sagging_settings(8, CholmodFactorKind::kSimplicial);
  auto half = test::make_body(supernodal, mesh, test::fixed_x0(mesh));
  auto full = test::make_body(simplicial, mesh, test::fixed_x0(mesh));
  ASSERT_NE(half, nullptr);
  ASSERT_NE(full, nullptr);
  ASSERT_TRUE(half->supernodal_factor());
  ASSERT_FALSE(full->supernodal_factor());
  SphereLinks links;
  const std::array<double, 4> w = {0.1, 0.2, 0.3, 0.4};
  for (const std::size_t tet : {std::size_t{0}, std::size_t{7}, mesh.tets.size() / 2,
                                mesh.tets.size() - 1, mesh.tets.size() - 9})
    ASSERT_EQ(links.add_sphere(mesh.tets[tet], w, 0.001), "");
  // Four: within the budget of kept columns solved again on a new factor.
  const std::vector<std::uint32_t> spheres = {3, 0, 4, 1};
  const std::size_t n = 9 * spheres.size() * spheres.size();
  std::vector<float> w_half(n), w_full(n);
  const auto expect_same = [&](const char* when) {
    ASSERT_TRUE(half->compliance(spheres, links, w_half)) << when;
    ASSERT_TRUE(full->compliance(spheres, links, w_full)) << when;
    float largest = 0.0f;
    for (const float v : w_full) largest = std::max(largest, std::abs(v));
    ASSERT_GT(largest, 0.0f);
    for (std::size_t i = 0; i < n; ++i)
      EXPECT_NEAR(w_half[i], w_full[i], 1e-5f * largest) << when << " entry " << i;
  };
  expect_same("at rest");
  for (int k = 0; k < 20; ++k) {
    half->step();
    full->step();
  }
  expect_same("sagged");
}

class KeptColumns : public testing::TestWithParam<CholmodFactorKind> {};

TEST_P(KeptColumns, GiveTheBlockOfAFreshSolveUntilTheFactorChanges) {
  // A body that solved other spheres before (some of them kept) writes the
  // same block as a body solving these spheres for the first time; after a
  // refactorisation at a deformed state nothing kept is reused. Full solves
  // (simplicial) and half solves (supernodal) alike.
  const BodyMesh mesh = test::bar_mesh(2);
  const BodySettings settings = sagging_settings(4, GetParam());
  const SphereLinks links = tip_spheres(mesh, 6);
  auto used = test::make_body(settings, mesh, test::fixed_x0(mesh));
  auto fresh = test::make_body(settings, mesh, test::fixed_x0(mesh));
  ASSERT_NE(used, nullptr);
  ASSERT_NE(fresh, nullptr);
  std::vector<float> w_used(std::size_t{9} * 16);
  std::vector<float> w_fresh(std::size_t{9} * 16);
  const auto expect_same = [&](const std::vector<std::uint32_t>& spheres, const char* when) {
    ASSERT_TRUE(used->compliance(spheres, links, w_used)) << when;
    ASSERT_TRUE(fresh->compliance(spheres, links, w_fresh)) << when;
    const std::size_t n = 9 * spheres.size() * spheres.size();
    float largest = 0.0f;
    for (std::size_t i = 0; i < n; ++i) largest = std::max(largest, std::abs(w_fresh[i]));
    for (std::size_t i = 0; i < n; ++i)
      EXPECT_NEAR(w_used[i], w_fresh[i], 1e-6f * largest) << when << " entry " << i;
  };
  std::vector<float> scratch(std::size_t{9} * 16);
  ASSERT_TRUE(used->compliance(std::vector<std::uint32_t>{0, 1, 2}, links, scratch));
  ASSERT_TRUE(used->compliance(std::vector<std::uint32_t>{3, 4}, links, scratch));
  expect_same({4, 1, 5, 2}, "kept columns, new order");
  // Both sag under gravity with a factorisation every step (the default).
  for (int k = 0; k < 30; ++k) {
    used->step();
    fresh->step();
  }
  expect_same({1, 4, 2}, "after refactorisations");
}

INSTANTIATE_TEST_SUITE_P(Compliance, KeptColumns,
                         testing::Values(CholmodFactorKind::kSimplicial,
                                         CholmodFactorKind::kSupernodal));

TEST(Compliance, TheRefreshBudgetLeavesColumnsOfAnOlderFactorUnlessRaised) {
  // Eight spheres solved at rest, then thirty refactorisations while the bar
  // sags: with the default budget (four spheres a call) half of the block
  // still comes from the rest factor and differs from a fresh body's; with
  // the budget raised to the block every column is solved again.
  const BodyMesh mesh = test::bar_mesh(3);
  const BodySettings settings = sagging_settings(8, CholmodFactorKind::kSupernodal);
  const SphereLinks links = tip_spheres(mesh, 8);
  const std::vector<std::uint32_t> spheres = {0, 1, 2, 3, 4, 5, 6, 7};
  const std::size_t n = 9 * spheres.size() * spheres.size();
  const auto largest_difference = [&](std::size_t budget) {
    auto used = test::make_body(settings, mesh, test::fixed_x0(mesh));
    auto fresh = test::make_body(settings, mesh, test::fixed_x0(mesh));
    EXPECT_NE(used, nullptr);
    EXPECT_NE(fresh, nullptr);
    if (used == nullptr || fresh == nullptr) return -1.0f;
    if (budget > 0) used->set_compliance_refresh(budget);
    std::vector<float> w_used(n), w_fresh(n);
    EXPECT_TRUE(used->compliance(spheres, links, w_used));
    for (int k = 0; k < 30; ++k) {
      used->step();
      fresh->step();
    }
    EXPECT_TRUE(used->compliance(spheres, links, w_used));
    EXPECT_TRUE(fresh->compliance(spheres, links, w_fresh));
    float largest = 0.0f;
    float difference = 0.0f;
    for (std::size_t i = 0; i < n; ++i) {
      largest = std::max(largest, std::abs(w_fresh[i]));
      difference = std::max(difference, std::abs(w_used[i] - w_fresh[i]));
    }
    return difference / largest;
  };
  EXPECT_GT(largest_difference(0), 1e-4f);  // the default budget: lagged columns
  EXPECT_LT(largest_difference(8), 1e-6f);  // every column on the new factor
}

TEST(Compliance, TheRefreshBudgetServesTheLeadingSpheresBeforeStalerOnes) {
  // Spheres 4-7 solved at rest, 0-3 ten refactorisations later, then ten
  // more: asked for 0-7 in that order with the default budget (four a
  // call), the two leading spheres (the rows the tick solved, the deepest
  // first) are solved on the new factor although 4-7 are staler, and the
  // two after them are not (the other half of the budget went to 4 and 5).
  const BodyMesh mesh = test::bar_mesh(3);
  const BodySettings settings = sagging_settings(8, CholmodFactorKind::kSupernodal);
  const SphereLinks links = tip_spheres(mesh, 8);
  auto used = test::make_body(settings, mesh, test::fixed_x0(mesh));
  auto fresh = test::make_body(settings, mesh, test::fixed_x0(mesh));
  ASSERT_NE(used, nullptr);
  ASSERT_NE(fresh, nullptr);
  const std::vector<std::uint32_t> spheres = {0, 1, 2, 3, 4, 5, 6, 7};
  const std::size_t rows = 3 * spheres.size();
  std::vector<float> w_used(rows * rows), w_fresh(rows * rows);
  ASSERT_TRUE(used->compliance(std::vector<std::uint32_t>{4, 5, 6, 7}, links, w_used));
  for (int k = 0; k < 10; ++k) {
    used->step();
    fresh->step();
  }
  ASSERT_TRUE(used->compliance(std::vector<std::uint32_t>{0, 1, 2, 3}, links, w_used));
  for (int k = 0; k < 10; ++k) {
    used->step();
    fresh->step();
  }
  ASSERT_TRUE(used->compliance(spheres, links, w_used));
  ASSERT_TRUE(fresh->compliance(spheres, links, w_fresh));
  // The largest difference within the diagonal blocks of spheres [first, end),
  // relative to the largest entry of the fresh block.
  float largest = 0.0f;
  for (const float w : w_fresh) largest = std::max(largest, std::abs(w));
  const auto difference = [&](std::size_t first, std::size_t end) {
    float worst = 0.0f;
    for (std::size_t r = 3 * first; r < 3 * end; ++r) {
      for (std::size_t c = 3 * first; c < 3 * end; ++c)
        worst = std::max(worst, std::abs(w_used[r * rows + c] - w_fresh[r * rows + c]));
    }
    return worst / largest;
  };
  EXPECT_LT(difference(0, 2), 1e-6f);  // the leading two: on the new factor
  EXPECT_GT(difference(2, 4), 1e-4f);  // the next two: still from ten factorisations ago
}

// W of the listed spheres from full solves on the body's factor in use
// (Body::step_motion, h^2 A^-1 f), independent of the compliance block.
std::vector<float> block_from_step_motion(Body& body, const SphereLinks& links,
                                          const std::vector<std::uint32_t>& spheres) {
  const std::size_t rows = 3 * spheres.size();
  const std::size_t dofs = 3 * body.node_count();
  std::vector<float> w(rows * rows, 0.0f);
  std::vector<double> force(dofs), motion(dofs);
  for (std::size_t t = 0; t < spheres.size(); ++t) {
    for (std::size_t e = 0; e < 3; ++e) {
      std::fill(force.begin(), force.end(), 0.0);
      const auto nodes = links.nodes(spheres[t]);
      const auto weights = links.weights(spheres[t]);
      for (std::size_t m = 0; m < nodes.size(); ++m)
        force[3 * std::size_t{nodes[m]} + e] += weights[m];
      EXPECT_TRUE(body.step_motion(force, motion));
      for (std::size_t s = 0; s < spheres.size(); ++s) {
        const auto nodes_s = links.nodes(spheres[s]);
        const auto weights_s = links.weights(spheres[s]);
        for (std::size_t d = 0; d < 3; ++d) {
          double sum = 0.0;
          for (std::size_t m = 0; m < nodes_s.size(); ++m)
            sum += weights_s[m] * motion[3 * std::size_t{nodes_s[m]} + d];
          w[(3 * s + d) * rows + 3 * t + e] = static_cast<float>(sum);
        }
      }
    }
  }
  return w;
}

TEST(Compliance, TheFactorisationsThreadBringsTheBlockAlongToTheFactorItInstalls) {
  // A bar sagging under gravity, factorised every fourth step in the
  // background (installed three steps after it began), with no refresh
  // budget on the step: the block the install brings is solved on the new
  // factor, so after thirty steps W equals full solves on the factor in
  // use; without the thread's refresh it is still the rest factor's. Then
  // the spheres asked for change every step (eight of sixteen in a block
  // of eight), so between a factorisation's begin and its install the
  // listed spheres lose slots to others: a slot taken by another sphere
  // must not be given the listed sphere's columns.
  const BodyMesh mesh = test::bar_mesh(3);
  BodySettings settings = sagging_settings(8, CholmodFactorKind::kSupernodal);
  settings.solver.refactor_period = 4;
  settings.solver.background_factor_latency_s = 0.03;  // three 10 ms steps
  const SphereLinks links = tip_spheres(mesh, 16);
  const std::vector<std::uint32_t> first = {0, 1, 2, 3, 4, 5, 6, 7};
  const std::size_t rows = 3 * first.size();
  const auto largest_difference = [&](bool with_factor, bool alternate) {
    auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
    EXPECT_NE(body, nullptr);
    if (body == nullptr) return -1.0f;
    // Alternating, the spheres of the set not listed at a begin keep older
    // columns: the step's budget refreshes them (it skips adopted slots).
    body->set_compliance_refresh(alternate ? 8 : 0);
    body->set_compliance_refresh_with_factor(with_factor);
    std::vector<float> w(rows * rows);
    float worst = 0.0f;  // over every step's block
    for (int k = 0; k < 30; ++k) {
      // Alternating: eight of the sixteen, starting three further on each step.
      std::vector<std::uint32_t> spheres = first;
      if (alternate) {
        for (std::size_t i = 0; i < spheres.size(); ++i)
          spheres[i] =
              static_cast<std::uint32_t>((std::size_t{3} * static_cast<std::size_t>(k) + i) % 16);
      }
      EXPECT_TRUE(body->compliance(spheres, links, w));
      const std::vector<float> truth = block_from_step_motion(*body, links, spheres);
      float largest = 0.0f;
      float difference = 0.0f;
      for (std::size_t i = 0; i < w.size(); ++i) {
        largest = std::max(largest, std::abs(truth[i]));
        difference = std::max(difference, std::abs(w[i] - truth[i]));
      }
      worst = std::max(worst, difference / largest);
      body->step();
    }
    EXPECT_EQ(body->compliance_refreshes_adopted() > 0, with_factor);
    return worst;
  };
  EXPECT_GT(largest_difference(false, false), 1e-3f);  // the rest factor's columns
  EXPECT_LT(largest_difference(true, false), 1e-5f);
  EXPECT_LT(largest_difference(true, true), 1e-5f);
}

TEST(Sleep, RestingBodySleepsAndWakesOnTouch) {
  const BodyMesh mesh = test::bar_mesh(2);
  BodySettings settings;
  settings.time_step = std::chrono::milliseconds(10);
  auto body = test::make_body(settings, mesh, test::fixed_x0(mesh));
  ASSERT_NE(body, nullptr);
  int asleep_at = -1;
  for (int k = 0; k < 2000 && asleep_at < 0; ++k) {
    if (body->step().asleep || body->asleep()) asleep_at = k;
  }
  ASSERT_GE(asleep_at, 0) << "never fell asleep";
  const std::vector<double> rest(body->positions_m().begin(), body->positions_m().end());
  for (int k = 0; k < 10; ++k) EXPECT_TRUE(body->step().asleep);
  for (std::size_t i = 0; i < rest.size(); ++i) ASSERT_EQ(rest[i], body->positions_m()[i]);
  // A candidate-only contact does not wake; an active one does.
  SphereLinks links = tip_spheres(mesh, 1);
  ContactSet set;
  Contact contact;
  contact.state = ContactState::kCandidate;
  set.contacts.push_back(contact);
  set.state_step = body->step_index();
  EXPECT_TRUE(body->step(&set, &links).asleep);
  set.contacts[0].state = ContactState::kActive;
  set.contacts[0].plane_point_m = Eigen::Vector3d(0, -1.0, 0);  // far below: touching, not violated
  set.state_step = body->step_index();
  EXPECT_FALSE(body->step(&set, &links).asleep);
  // An external force wakes as well.
  for (int k = 0; k < 2000 && !body->asleep(); ++k) body->step();
  ASSERT_TRUE(body->asleep());
  body->set_external_force(0, Eigen::Vector3d(0, 0.01, 0));
  EXPECT_FALSE(body->step().asleep);
}

}  // namespace
}  // namespace fahr::fem
