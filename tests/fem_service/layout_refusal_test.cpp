// The FEM service refuses a ContactSet whose sphere layout fingerprint is
// not its own: nothing of it is applied (the body stays where it was), the
// error names both fingerprints, once per change; with its own fingerprint
// the same set is applied.
#include <gtest/gtest.h>

#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "contact_set.h"
#include "fahr/fem_service/fem_body_setup.h"
#include "fahr/fem_service/layout_check.h"
#include "fahr/fem_service/service_step.h"
#include "fahr/scene/load_scene.h"
#include "fahr/scene/plan.h"

namespace fahr::fem_service {
namespace {

// The shipped scene without gravity and without the anatomy pass, so a body
// left alone stays at rest and any motion is the ContactSet's.
struct StillTongue {
  std::shared_ptr<scene::Scene> scene;
  FemBodySetup setup;
  StillTongue() {
    scene = std::make_shared<scene::Scene>(
        *scene::load_scene(FAHR_SOURCE_DIR "/deployment/scenes/neonatal_intubation.yaml"));
    scene->gravity_mps2 = Eigen::Vector3d::Zero();
    const scene::ServicePlan plan = scene::derive_plan(*scene);
    setup = set_up_body(*scene, scene->bodies[plan.fem_bodies.front()]);
    setup.enforce_anatomy = false;
  }
};

// The sphere with the highest rest centre (the dorsum, under a blade).
std::uint32_t top_sphere(const FemBodySetup& setup) {
  const auto x = setup.body->positions_m();
  std::uint32_t best = 0;
  double best_y = -1e9;
  for (std::uint32_t s = 0; s < setup.links.size(); ++s) {
    const double y = setup.links.centre(s, x.data()).y();
    if (y > best_y) {
      best_y = y;
      best = s;
    }
  }
  return best;
}

// A tool plane 1 mm into the sphere from above: an active constraint that
// moves its centre down by more than 1 mm, and a push of 0.5 N.
msg::ContactSet pressing_set(const FemBodySetup& setup, std::uint32_t sphere,
                             std::uint64_t fingerprint) {
  const Eigen::Vector3d c = setup.links.centre(sphere, setup.body->positions_m().data());
  msg::ContactSet set;
  set.body_id(setup.scene_body->id);
  set.fem_step(setup.body->step_index());
  set.layout_fingerprint(fingerprint);
  msg::Contact contact;
  contact.sphere_id(sphere);
  contact.kind(msg::CONTACT_TOOL);
  contact.state(msg::CONSTRAINT_ACTIVE);
  contact.point_m().x(c.x());
  contact.point_m().y(c.y() - 1e-3);
  contact.point_m().z(c.z());
  contact.normal().y(-1.0);
  contact.hold_centre_m().x(c.x());
  contact.hold_centre_m().y(c.y());
  contact.hold_centre_m().z(c.z());
  contact.penetration_m(1e-3 + setup.links.radius_m(sphere));
  contact.force_n(0.5);
  set.contacts().push_back(contact);
  return set;
}

// Largest distance of a node from its rest position, m.
double largest_motion_m(const FemBodySetup& setup) {
  const auto x = setup.body->positions_m();
  double largest = 0.0;
  for (std::size_t n = 0; n < setup.mesh.node_count(); ++n) {
    const Eigen::Vector3d p(x[3 * n], x[3 * n + 1], x[3 * n + 2]);
    largest = std::max(largest, (p - setup.mesh.rest_positions()[n]).norm());
  }
  return largest;
}

std::string hex(std::uint64_t value) {
  char text[24];
  std::snprintf(text, sizeof(text), "0x%016llx", static_cast<unsigned long long>(value));
  return text;
}

TEST(LayoutRefusal, AnotherLayoutIsRefusedWithBothFingerprintsAndItsOwnIsApplied) {
  StillTongue tongue;
  FemBodySetup& setup = tongue.setup;
  ServiceStep step(setup);
  const std::uint64_t ours = setup.layout_fingerprint;
  const std::uint64_t theirs = ours ^ 0x5a5a000000000001ULL;
  ASSERT_EQ(step.layout_check().ours(), ours);
  const std::uint32_t sphere = top_sphere(setup);

  // Another layout: refused, nothing applied, the body stays at rest.
  for (std::uint64_t seq = 1; seq <= 4; ++seq) {
    step.take(pressing_set(setup, sphere, theirs), seq);
    step.step();
    EXPECT_FALSE(step.last_report().contacts_applied);
    EXPECT_EQ(step.state().applied_contact_seq(), 0u);
  }
  EXPECT_LT(largest_motion_m(setup), 1e-9) << "a refused set moved the body";
  EXPECT_EQ(step.layout_check().refused(), 4u);
  // One error for the change, naming both fingerprints; none for the repeats.
  const std::string error = step.layout_check().take_error();
  EXPECT_NE(error.find(hex(theirs)), std::string::npos) << error;
  EXPECT_NE(error.find(hex(ours)), std::string::npos) << error;
  EXPECT_EQ(step.layout_check().take_error(), "");
  std::vector<std::pair<std::string, double>> metrics;
  step.metrics(metrics);
  const auto refused = std::find_if(metrics.begin(), metrics.end(),
                                    [](const auto& m) { return m.first == "layout_refused_sets"; });
  ASSERT_NE(refused, metrics.end());
  EXPECT_EQ(refused->second, 4.0);

  // Its own layout: the same set is applied and moves the sphere down.
  const Eigen::Vector3d before = setup.links.centre(sphere, setup.body->positions_m().data());
  step.take(pressing_set(setup, sphere, ours), 5);
  step.step();
  EXPECT_TRUE(step.last_report().contacts_applied);
  EXPECT_EQ(step.state().applied_contact_seq(), 5u);
  const Eigen::Vector3d after = setup.links.centre(sphere, setup.body->positions_m().data());
  EXPECT_LT(after.y() - before.y(), -0.5e-3) << "the accepted set did not press the sphere";
  EXPECT_EQ(step.layout_check().refused(), 4u);
  EXPECT_EQ(step.layout_check().take_error(), "") << "accepting is no error";

  // Away again, to the same foreign layout: a change, so a new error.
  step.take(pressing_set(setup, sphere, theirs), 6);
  EXPECT_NE(step.layout_check().take_error(), "");
  // And to a third one.
  step.take(pressing_set(setup, sphere, theirs + 1), 7);
  const std::string third = step.layout_check().take_error();
  EXPECT_NE(third.find(hex(theirs + 1)), std::string::npos) << third;
  EXPECT_EQ(step.layout_check().refused(), 6u);
}

// A set with a non-finite number anywhere the FEM would read it is refused
// whole and counted; one error sentence per report says so; a finite set
// after it is applied.
TEST(NonFiniteRefusal, ASetWithANonFiniteNumberIsNeverUsed) {
  StillTongue tongue;
  FemBodySetup& setup = tongue.setup;
  ServiceStep step(setup);
  const std::uint64_t ours = setup.layout_fingerprint;
  const std::uint32_t sphere = top_sphere(setup);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<msg::ContactSet> bad(6, pressing_set(setup, sphere, ours));
  bad[0].contacts()[0].normal().x(nan);
  bad[1].contacts()[0].point_m().z(inf);
  bad[2].contacts()[0].force_n(nan);
  bad[3].contacts()[0].penetration_m(-inf);
  bad[4].contacts()[0].hold_centre_m().y(nan);
  bad[5].world_from_tool().orientation().w(nan);
  std::uint64_t seq = 1;
  for (const msg::ContactSet& set : bad) {
    step.take(set, seq++);
    step.step();
    EXPECT_FALSE(step.last_report().contacts_applied) << "set " << seq - 1;
    EXPECT_EQ(step.state().applied_contact_seq(), 0u);
  }
  EXPECT_LT(largest_motion_m(setup), 1e-9) << "a refused set moved the body";
  EXPECT_EQ(step.non_finite_sets(), bad.size());
  std::vector<std::string> errors;
  step.take_errors(errors);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("non-finite"), std::string::npos) << errors[0];
  errors.clear();
  step.take_errors(errors);
  EXPECT_TRUE(errors.empty()) << "said twice";

  step.take(pressing_set(setup, sphere, ours), seq);
  step.step();
  EXPECT_TRUE(step.last_report().contacts_applied);
  EXPECT_EQ(step.non_finite_sets(), bad.size());
}

// A set naming a sphere the layout does not have (a hostile or broken
// writer: the fingerprint alone does not prove the ids) is refused whole and
// counted, however many of its contacts are good.
TEST(UnknownSphereRefusal, ASetNamingASphereTheLayoutLacksIsNeverUsed) {
  StillTongue tongue;
  FemBodySetup& setup = tongue.setup;
  ServiceStep step(setup);
  const std::uint64_t ours = setup.layout_fingerprint;
  msg::ContactSet set = pressing_set(setup, top_sphere(setup), ours);
  msg::Contact unknown = set.contacts()[0];
  unknown.sphere_id(static_cast<std::uint32_t>(setup.links.size()));
  set.contacts().push_back(unknown);
  step.take(set, 1);
  step.step();
  EXPECT_FALSE(step.last_report().contacts_applied);
  EXPECT_LT(largest_motion_m(setup), 1e-9) << "a refused set moved the body";
  EXPECT_EQ(step.unknown_sphere_sets(), 1u);
  std::vector<std::string> errors;
  step.take_errors(errors);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("sphere"), std::string::npos) << errors[0];
  set.contacts().pop_back();
  step.take(set, 2);
  step.step();
  EXPECT_TRUE(step.last_report().contacts_applied);
}

TEST(LayoutRefusal, TheErrorIsOneSentenceNamingBothInHex) {
  const std::string error =
      LayoutCheck::mismatch_error(0x00000000000000ffULL, 0xfedcba9876543210ULL);
  EXPECT_NE(error.find("0x00000000000000ff"), std::string::npos) << error;
  EXPECT_NE(error.find("0xfedcba9876543210"), std::string::npos) << error;
  EXPECT_EQ(error.find('\n'), std::string::npos);
  EXPECT_LE(error.size(), 200u) << "ServiceError.text holds 200 characters";
}

}  // namespace
}  // namespace fahr::fem_service

namespace fahr::fem_service {
namespace {

// After a divergence reset the tongue is at rest; a ContactSet computed on a
// state before the reset describes the diverged tongue, and its blade, deep
// in the rested one, would shove nodes far in one step. Such a set is
// ignored and counted stale; one computed on the rested tongue is applied.
TEST(ResetRefusal, ASetComputedBeforeADivergenceResetIsNotApplied) {
  StillTongue tongue;
  FemBodySetup& setup = tongue.setup;
  ServiceStep step(setup);
  const std::uint32_t sphere = top_sphere(setup);
  const std::uint64_t ours = setup.layout_fingerprint;
  // A constraint 10 m deep: the projection moves the sphere's nodes farther
  // than twice the body's size, so the step resets the body.
  msg::ContactSet flinging = pressing_set(setup, sphere, ours);
  flinging.contacts()[0].point_m().y(flinging.contacts()[0].point_m().y() - 10.0);
  flinging.contacts()[0].penetration_m(10.0);
  const std::uint64_t before_reset = setup.body->step_index();
  step.take(flinging, 1);
  step.step();
  ASSERT_TRUE(step.last_report().diverged_reset);
  EXPECT_EQ(step.divergence_resets(), 1u);
  EXPECT_LT(largest_motion_m(setup), 1e-9);

  // A set computed on the last state before the reset (within the age limit).
  msg::ContactSet stale = pressing_set(setup, sphere, ours);
  stale.fem_step(before_reset);
  const std::uint64_t stale_before = step.stale_sets();
  step.take(stale, 2);
  step.step();
  EXPECT_FALSE(step.last_report().contacts_applied);
  EXPECT_EQ(step.state().applied_contact_seq(), 0u);
  EXPECT_EQ(step.stale_sets(), stale_before + 1);
  EXPECT_LT(largest_motion_m(setup), 1e-9) << "a set from before the reset moved the body";

  // A set computed on the rested tongue is applied.
  step.take(pressing_set(setup, sphere, ours), 3);
  step.step();
  EXPECT_TRUE(step.last_report().contacts_applied);
  EXPECT_EQ(step.state().applied_contact_seq(), 3u);
  EXPECT_GT(largest_motion_m(setup), 0.5e-3);
}

// A haptic service whose snapshot lags behind a slow FEM answers an older
// state than the FEM's newest; its set is still where the tool is and is
// applied. Only a sender gone silent (no newer set for the maximum age)
// has its last set run out: the tongue is released.
TEST(StaleRule, ASetAnsweringAnOlderStateIsAppliedUntilTheSenderIsSilent) {
  StillTongue tongue;
  FemBodySetup& setup = tongue.setup;
  ServiceStep step(setup);
  const std::uint32_t sphere = top_sphere(setup);
  const std::uint64_t age = setup.settings.max_contact_age_steps;
  for (std::uint64_t k = 0; k < 3 * age; ++k) step.step();
  msg::ContactSet lagging = pressing_set(setup, sphere, setup.layout_fingerprint);
  lagging.fem_step(setup.body->step_index() - 2 * age);
  step.take(lagging, 1);
  for (std::uint64_t k = 0; k <= age; ++k) {
    step.step();
    EXPECT_TRUE(step.last_report().contacts_applied) << "step " << k << " after it arrived";
    EXPECT_EQ(step.state().applied_contact_seq(), 1u);
  }
  EXPECT_EQ(step.stale_sets(), 0u);
  EXPECT_GT(largest_motion_m(setup), 0.5e-3);
  step.step();
  EXPECT_FALSE(step.last_report().contacts_applied);
  EXPECT_EQ(step.state().applied_contact_seq(), 0u);
  EXPECT_EQ(step.stale_sets(), 1u);

  // In real time the age runs on the loop's clock: a FEM catching up runs
  // many steps back to back within the age, and the set stays applied.
  const std::int64_t t0 = 1'000'000'000;
  const auto age_ns =
      static_cast<std::int64_t>(static_cast<double>(age) * setup.body->time_step_s() * 1e9);
  step.take(pressing_set(setup, sphere, setup.layout_fingerprint), 2, t0);
  for (std::uint64_t k = 0; k < 4 * age; ++k) {
    step.step(t0 + age_ns / 2);
    EXPECT_TRUE(step.last_report().contacts_applied) << "step " << k << " after it arrived";
  }
  step.step(t0 + age_ns + 1);
  EXPECT_FALSE(step.last_report().contacts_applied);
  EXPECT_EQ(step.stale_sets(), 2u);
  // The first silence (one stale step) ended with the set at t0: the sender
  // was late. The second has no newer set after it yet: it may be the
  // sender's end.
  EXPECT_EQ(step.stale_sets_followed(), 1u);
  step.step(t0 + age_ns + 2);
  step.step(t0 + age_ns + 3);
  EXPECT_EQ(step.stale_sets(), 4u);
  EXPECT_EQ(step.stale_sets_followed(), 1u);
  // A newer set ends it: its three stale steps were a late sender's too.
  step.take(pressing_set(setup, sphere, setup.layout_fingerprint), 3, t0 + age_ns + 4);
  step.step(t0 + age_ns + 5);
  EXPECT_TRUE(step.last_report().contacts_applied);
  EXPECT_EQ(step.stale_sets(), 4u);
  EXPECT_EQ(step.stale_sets_followed(), 4u);
}

}  // namespace
}  // namespace fahr::fem_service
