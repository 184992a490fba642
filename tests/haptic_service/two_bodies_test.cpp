// Two deformable bodies as one tissue: the shipped scene with a copy of the
// tongue 20 mm above it (tongue_b, id 2). The haptic set-up joins their
// layouts, the digest places each body's state and W block in the joined
// tissue (zero between the bodies), the real-time feed routes each body's
// states by its key, and the tick's ContactSet splits back into one per
// body with the body's own sphere ids and fingerprint.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <memory>
#include <thread>
#include <vector>

#include "contact_set.h"
#include "deformation_state.h"
#include "fahr/common/packed_symmetric.h"
#include "fahr/common/participant.h"
#include "fahr/common/publisher.h"
#include "fahr/haptic_service/haptic_loop.h"
#include "fahr/haptic_service/haptic_setup.h"
#include "fahr/haptic_service/scene_publication.h"
#include "fahr/haptic_service/tissue_feed.h"
#include "fahr/haptic_service/tissue_snapshot.h"
#include "fahr/scene/load_scene.h"

namespace fahr::haptic_service {
namespace {

constexpr double kLiftM = 0.02;  // tongue_b's offset above the tongue

struct TwoTongues {
  std::shared_ptr<scene::Scene> scene;
  HapticSetup setup;
};

const TwoTongues& two_tongues() {
  static const TwoTongues loaded = [] {
    TwoTongues t;
    t.scene = std::make_shared<scene::Scene>(
        *scene::load_scene(FAHR_SOURCE_DIR "/deployment/scenes/neonatal_intubation.yaml"));
    scene::Body copy = t.scene->bodies.front();
    EXPECT_EQ(copy.name, "tongue");
    copy.name = "tongue_b";
    copy.id = 2;
    copy.pose.position_m.y() += kLiftM;
    t.scene->bodies.push_back(copy);
    t.setup = set_up(*t.scene);
    return t;
  }();
  return loaded;
}

// Body b's nodes at rest moved by `shift`, with W for `spheres` (its own
// ids): a diagonal 3x3 block of `w` each.
msg::DeformationState state_of(const TissueBody& body, const Eigen::Vector3d& shift,
                               const std::vector<std::uint32_t>& spheres, float w,
                               std::uint64_t step) {
  msg::DeformationState state;
  state.body_id(body.body->id);
  state.step(step);
  for (const Eigen::Vector3d& x : body.mesh.rest_positions()) {
    for (int a = 0; a < 3; ++a) state.positions_m().push_back(static_cast<float>(x[a] + shift[a]));
  }
  state.compliance_sphere_ids(spheres);
  const std::size_t n = 3 * spheres.size();
  state.compliance_mpn().assign(common::packed_upper_size(n), 0.0f);
  for (std::size_t i = 0; i < n; ++i)
    state.compliance_mpn()[common::packed_upper_index(n, i, i)] = w;
  return state;
}

TEST(TwoBodies, TheTissueJoinsBothLayoutsAndEachIsDescribedAlone) {
  const HapticSetup& setup = two_tongues().setup;
  ASSERT_EQ(setup.bodies.size(), 2u);
  const TissueBody& a = setup.bodies[0];
  const TissueBody& b = setup.bodies[1];
  EXPECT_EQ(b.first_sphere, a.layout.size());
  EXPECT_EQ(b.first_node, a.mesh.node_count());
  EXPECT_EQ(setup.layout.size(), a.layout.size() + b.layout.size());
  EXPECT_EQ(setup.mesh.node_count(), a.mesh.node_count() + b.mesh.node_count());
  // The copy's spheres are the tongue's, lifted: the same filling on the
  // moved mesh (its fingerprint differs with the coordinates).
  ASSERT_EQ(a.layout.size(), b.layout.size());
  EXPECT_NE(a.layout_fingerprint, b.layout_fingerprint);
  for (std::size_t s = 0; s < a.layout.size(); s += 97) {
    const Eigen::Vector3d lifted = a.layout.sphere(s).rest_centre_m + Eigen::Vector3d(0, kLiftM, 0);
    EXPECT_LT((setup.layout.sphere(b.first_sphere + s).rest_centre_m - lifted).norm(), 1e-9);
  }
  EXPECT_EQ(body_of_sphere(setup, b.first_sphere - 1), 0u);
  EXPECT_EQ(body_of_sphere(setup, b.first_sphere), 1u);
  // One SceneDescription per deformable body, with its own mesh and layout.
  for (const msg::SceneDescription& d : describe_scene(setup)) {
    if (d.body_id() != a.body->id && d.body_id() != b.body->id) continue;
    const TissueBody& own = d.body_id() == a.body->id ? a : b;
    EXPECT_EQ(d.layout_fingerprint(), own.layout_fingerprint) << d.body_name();
    EXPECT_EQ(d.rest_positions_m().size(), 3 * own.mesh.node_count()) << d.body_name();
    EXPECT_EQ(d.sphere_rest_m().size(), 4 * own.layout.size()) << d.body_name();
  }
}

TEST(TwoBodies, TheDigestPlacesEachStateAndItsWBlockOnTheDiagonal) {
  const HapticSetup& setup = two_tongues().setup;
  TissueDigest digest(setup);
  TissueSnapshot snapshot = digest.make_snapshot();
  const TissueBody& a = setup.bodies[0];
  const TissueBody& b = setup.bodies[1];
  const Eigen::Vector3d shift(0.001, 0, 0);
  const msg::DeformationState sa = state_of(a, Eigen::Vector3d::Zero(), {5, 9}, 1e-3f, 40);
  const msg::DeformationState sb = state_of(b, shift, {3}, 2e-3f, 41);
  // Either body's state alone, or in the wrong order, is refused.
  std::vector<const msg::DeformationState*> states{&sa};
  EXPECT_FALSE(digest.digest(states, snapshot));
  states = {&sb, &sa};
  EXPECT_FALSE(digest.digest(states, snapshot));
  states = {&sa, &sb};
  ASSERT_TRUE(digest.digest(states, snapshot));
  EXPECT_EQ(snapshot.fem_step, 40u);
  EXPECT_EQ(snapshot.body_fem_steps, (std::vector<std::uint64_t>{40, 41}));
  // Body b's spheres moved with its nodes, body a's did not.
  const auto centres = snapshot.spheres.centres_m();
  EXPECT_LT(
      (centres[b.first_sphere + 3] - setup.layout.sphere(b.first_sphere + 3).rest_centre_m - shift)
          .norm(),
      1e-6);
  EXPECT_LT((centres[5] - setup.layout.sphere(5).rest_centre_m).norm(), 1e-6);
  // W: a's two spheres, then b's one, in joined ids; block-diagonal.
  ASSERT_EQ(snapshot.compliance_count, 3u);
  EXPECT_EQ(snapshot.compliance_ids[2], b.first_sphere + 3);
  EXPECT_EQ(snapshot.compliance_index[b.first_sphere + 3], 2);
  EXPECT_EQ(snapshot.compliance_index[3], contact::kNoCompliance);
  const contact::TissueCompliance w = snapshot.compliance();
  ASSERT_TRUE(w.valid());
  const Eigen::Vector3d y = Eigen::Vector3d::UnitY();
  EXPECT_NEAR(w.normal_compliance(0, y, 0, y), 1e-3, 1e-9);
  EXPECT_NEAR(w.normal_compliance(2, y, 2, y), 2e-3, 1e-9);
  EXPECT_EQ(w.normal_compliance(0, y, 2, y), 0.0);
  EXPECT_EQ(w.normal_compliance(2, y, 1, y), 0.0);
}

TEST(TwoBodies, TheFeedRoutesEachBodysStatesByItsKey) {
  const HapticSetup& setup = two_tongues().setup;
  common::TransportConfig config;
  config.vendor = common::Vendor::kInProcess;
  config.domain_id = 31;
  common::Participant fem(config);
  common::Participant haptic(config);
  TissueFeed feed(haptic, setup);
  // One writer per body, as the FEM service has.
  common::Publisher<msg::DeformationState> out_a(fem);
  common::Publisher<msg::DeformationState> out_b(fem);
  msg::DeformationState sa = state_of(setup.bodies[0], Eigen::Vector3d::Zero(), {7}, 1e-3f, 12);
  msg::DeformationState sb =
      state_of(setup.bodies[1], Eigen::Vector3d(0, 0.001, 0), {8}, 2e-3f, 12);
  // A state of the first body only is not digested: the tissue waits for all.
  out_a.write(sa);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_EQ(feed.last_state_ns(), 0);
  out_b.write(sb);
  for (int i = 0; i < 100 && feed.last_state_ns() == 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  ASSERT_NE(feed.last_state_ns(), 0);
  const TissueSnapshot& tissue = feed.newest();
  EXPECT_TRUE(tissue.from_fem);
  ASSERT_EQ(tissue.compliance_count, 2u);
  EXPECT_EQ(tissue.compliance_ids[0], 7u);
  EXPECT_EQ(tissue.compliance_ids[1], setup.bodies[1].first_sphere + 8);
  // The topic's numbers are one sequence for both writers.
  EXPECT_EQ(sa.header().seq(), 1u);
  EXPECT_EQ(sb.header().seq(), 2u);
  EXPECT_EQ(feed.admission().foreign.load(), 0u);
  EXPECT_EQ(feed.admission().out_of_order.load(), 0u);
}

TEST(TwoBodies, TheTicksSetSplitsIntoOnePerBody) {
  const HapticSetup& setup = two_tongues().setup;
  TissueDigest digest(setup);
  TissueSnapshot tissue = digest.make_snapshot();
  const msg::DeformationState sa = state_of(setup.bodies[0], Eigen::Vector3d::Zero(), {}, 0, 20);
  const msg::DeformationState sb = state_of(setup.bodies[1], Eigen::Vector3d::Zero(), {}, 0, 21);
  const std::vector<const msg::DeformationState*> states{&sa, &sb};
  ASSERT_TRUE(digest.digest(states, tissue));
  const std::uint32_t first_b = setup.bodies[1].first_sphere;
  msg::ContactSet joined;
  joined.haptic_tick(77);
  joined.tool_frozen(true);
  joined.world_from_tool().position_m().x(0.03);
  for (const std::uint32_t id : {first_b + 4, 2u, first_b, 11u}) {
    msg::Contact c;
    c.sphere_id(id);
    c.force_n(0.1 * id);
    joined.contacts().push_back(c);
  }
  std::array<msg::ContactSet, 2> sets;
  for (auto& set : sets) set.contacts().reserve(msg::MAX_CONTACTS);
  const std::array<msg::ContactSet*, 2> out{&sets[0], &sets[1]};
  split_contacts(setup, tissue, joined, out);
  for (std::size_t b = 0; b < 2; ++b) {
    EXPECT_EQ(sets[b].body_id(), setup.bodies[b].body->id);
    EXPECT_EQ(sets[b].layout_fingerprint(), setup.bodies[b].layout_fingerprint);
    EXPECT_EQ(sets[b].fem_step(), 20u + b);
    EXPECT_EQ(sets[b].haptic_tick(), 77u);
    EXPECT_TRUE(sets[b].tool_frozen());
    EXPECT_EQ(sets[b].world_from_tool().position_m().x(), 0.03);
  }
  // In the tick's order, each with its body's own id.
  ASSERT_EQ(sets[0].contacts().size(), 2u);
  EXPECT_EQ(sets[0].contacts()[0].sphere_id(), 2u);
  EXPECT_EQ(sets[0].contacts()[1].sphere_id(), 11u);
  ASSERT_EQ(sets[1].contacts().size(), 2u);
  EXPECT_EQ(sets[1].contacts()[0].sphere_id(), 4u);
  EXPECT_EQ(sets[1].contacts()[1].sphere_id(), 0u);
  EXPECT_DOUBLE_EQ(sets[1].contacts()[0].force_n(), 0.1 * (first_b + 4));
}

}  // namespace
}  // namespace fahr::haptic_service
