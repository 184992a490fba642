// The FEM service and the haptic service, each from its own core, build the
// same sphere layout from one scene: the fingerprints agree, the haptic
// service's SceneDescription and ContactSets carry it, and the FEM service
// takes its ContactSets. A scene with another fill setting gives the FEM
// another layout, whose service refuses the same sets.
#include <gtest/gtest.h>

#include <memory>

#include "contact_set.h"
#include "fahr/fem_service/fem_body_setup.h"
#include "fahr/fem_service/service_step.h"
#include "fahr/haptic_service/haptic_loop.h"
#include "fahr/haptic_service/haptic_setup.h"
#include "fahr/haptic_service/scene_publication.h"
#include "fahr/haptic_service/tissue_snapshot.h"
#include "fahr/scene/load_scene.h"
#include "force_command.h"

namespace fahr::fem_service {
namespace {

std::shared_ptr<const scene::Scene> shipped_scene() {
  return scene::load_scene(FAHR_SOURCE_DIR "/deployment/scenes/neonatal_intubation.yaml");
}

// A ContactSet as the haptic service writes it: one tick of its loop, the
// stylus far from the tongue.
msg::ContactSet haptic_contact_set(const haptic_service::HapticSetup& setup,
                                   haptic_service::HapticLoop& loop) {
  haptic_service::TissueDigest digest(setup);
  const haptic_service::TissueSnapshot tissue = digest.make_snapshot();
  msg::DevicePose pose;
  pose.device_id(1);
  pose.world_from_stylus().position_m().x(0.2);  // 20 cm away
  pose.world_from_stylus().orientation().w(1.0);
  pose.renderable_force_n(7.9);
  pose.max_stiffness_npm(1480.0);
  msg::ForceCommand command;
  msg::ContactSet contacts;
  loop.tick(pose, tissue, command, contacts);
  return contacts;
}

TEST(LayoutAgreement, BothServicesBuildTheSameLayoutAndOtherSettingsDiffer) {
  const auto scene = shipped_scene();
  const haptic_service::HapticSetup haptic = haptic_service::set_up(*scene);
  haptic_service::HapticLoop loop(haptic);
  FemBodySetup fem = set_up_body(*scene, *haptic.bodies.front().body);

  // Equal, and published: in the SceneDescription of the deformable body
  // (0 for the rigid ones) and in every ContactSet.
  const std::uint64_t fingerprint = haptic.layout.fingerprint();
  EXPECT_EQ(fem.layout_fingerprint, fingerprint);
  EXPECT_EQ(fem.links.size(), haptic.layout.size());
  EXPECT_EQ(loop.layout_fingerprint(), fingerprint);
  for (const msg::SceneDescription& d : haptic_service::describe_scene(haptic)) {
    EXPECT_EQ(d.layout_fingerprint(),
              d.body_id() == haptic.bodies.front().body->id ? fingerprint : 0u)
        << d.body_name();
  }
  const msg::ContactSet set = haptic_contact_set(haptic, loop);
  EXPECT_EQ(set.layout_fingerprint(), fingerprint);

  // The FEM service takes it.
  ServiceStep step(fem);
  step.take(set, 1);
  step.step();
  EXPECT_EQ(step.layout_check().refused(), 0u);
  EXPECT_EQ(step.state().applied_contact_seq(), 1u);

  // One fill setting of the scene changed: the FEM's layout is another, and
  // its service refuses the haptic service's set.
  auto other = std::make_shared<scene::Scene>(*scene);
  scene::Body& tongue =
      other->bodies[static_cast<std::size_t>(haptic.bodies.front().body - scene->bodies.data())];
  tongue.deformable->aist.sphere_tet_volume_ratio *= 1.5;
  FemBodySetup other_fem = set_up_body(*other, tongue);
  EXPECT_NE(other_fem.layout_fingerprint, fingerprint);
  ServiceStep other_step(other_fem);
  other_step.take(set, 1);
  other_step.step();
  EXPECT_EQ(other_step.layout_check().refused(), 1u);
  EXPECT_EQ(other_step.state().applied_contact_seq(), 0u);
  EXPECT_NE(other_step.layout_check().take_error(), "");
}

}  // namespace
}  // namespace fahr::fem_service
