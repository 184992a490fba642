// The haptic service's tick on the neonatal scene, in one process: the
// blade stops at the palate (tool rows against the rigid anatomy), a tick
// and a state digest allocate nothing, bad FEM states are refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>
#include <numbers>
#include <vector>

#include "contact_set.h"
#include "fahr/collision/surface_samples.h"
#include "fahr/common/packed_symmetric.h"
#include "fahr/common/wire_eigen.h"
#include "fahr/device/trajectory.h"
#include "fahr/haptic_service/haptic_loop.h"
#include "fahr/haptic_service/tissue_snapshot.h"
#include "force_command.h"
#include "scene_fixture.h"

#ifndef FAHR_SANITIZE_BUILD
#include "allocation_counter.h"
#endif

namespace fahr::haptic_service::test {
namespace {

// The pressing pose of the gateway's scripts (meshes/neonatal/README.md).
const Eigen::Vector3d kPressTipM(-0.033, -0.0005, 0.0);
constexpr double kPressPitchDeg = 8.0;
// The intubation script's keyframe "insert between the lips, tip over the
// tongue" (libs/device/src/trajectory.cpp).
constexpr double kInsertedS = 3.5;
constexpr double kInsertedPitchDeg = 4.0;

// The pitch about +z of a script orientation, degrees.
double script_pitch_deg(const Eigen::Quaterniond& q) {
  return 2.0 * std::atan2(q.z(), q.w()) * 180.0 / std::numbers::pi;
}

// Deepest penetration of the tool's samples into `field` with the tool at
// `tip` (negative: the gap, when within 2 mm).
double tool_depth(const HapticSetup& setup, const RigidField& field, const Eigen::Vector3d& tip_m,
                  double pitch_deg) {
  const double half = 0.5 * pitch_deg * std::numbers::pi / 180.0;
  const Eigen::Quaterniond q(std::cos(half), 0.0, 0.0, std::sin(half));
  std::vector<collision::SurfaceContact> contacts(256);
  std::size_t n = 0;
  collision::query_surface_samples(setup.tool_samples, Eigen::Translation3d(tip_m) * q,
                                   rigid_body(field), 2e-3, contacts, n);
  double deepest = -std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < n; ++i) deepest = std::max(deepest, contacts[i].depth_m);
  return deepest;
}

// The deepest over every body the tool is tested against.
double anatomy_depth(const HapticSetup& setup, const Eigen::Vector3d& tip_m, double pitch_deg) {
  double deepest = -std::numeric_limits<double>::infinity();
  for (const std::size_t a : setup.tool_obstacles)
    deepest = std::max(deepest, tool_depth(setup, *setup.anatomy[a], tip_m, pitch_deg));
  return deepest;
}

using common::to_eigen;

// A DeformationState with the body at rest and no compliance yet.
msg::DeformationState rest_state(const HapticSetup& setup) {
  msg::DeformationState state;
  state.body_id(setup.bodies.front().body->id);
  for (const Eigen::Vector3d& x : setup.mesh.rest_positions()) {
    for (int a = 0; a < 3; ++a) state.positions_m().push_back(static_cast<float>(x[a]));
  }
  return state;
}

// The tongue at rest as the FEM would publish it once the ticks asked for
// W: a diagonal 3x3 block of `w_mpn` for each sphere the ContactSet names
// (rows and requests), as the FEM's block follows the ContactSet. No
// constant stands in for W in the tick, so a test that wants rows needs it.
msg::DeformationState rest_with_compliance(const HapticSetup& setup,
                                           const msg::ContactSet& contacts, std::uint64_t step,
                                           float w_mpn = 0.02f) {
  msg::DeformationState state = rest_state(setup);
  state.step(step);
  auto& ids = state.compliance_sphere_ids();
  for (const msg::Contact& c : contacts.contacts()) {
    if (ids.size() == msg::MAX_COMPLIANCE_SPHERES) break;
    if (std::find(ids.begin(), ids.end(), c.sphere_id()) == ids.end()) ids.push_back(c.sphere_id());
  }
  const std::size_t rows = 3 * ids.size();
  state.compliance_mpn().assign(common::packed_upper_size(rows), 0.0f);
  for (std::size_t r = 0; r < rows; ++r)
    state.compliance_mpn()[common::packed_upper_index(rows, r, r)] = w_mpn;
  return state;
}

TEST(HapticLoop, BladeStopsAtTheAnatomy) {
  const HapticSetup& setup = neonatal_scene().setup;
  // The blade enters the mouth as the intubation script has it (3.5 s, to
  // the tip over the tongue), then the hand lifts it 5 mm into what lies
  // above: the upper lip, then the palate.
  const device::Trajectory script = device::intubation_script();
  const auto inserted = script.at(std::chrono::duration<double>(kInsertedS));
  const double pitch_deg = kInsertedPitchDeg;
  double touch_y = inserted.position_m.y();
  while (!(anatomy_depth(setup, {inserted.position_m.x(), touch_y, 0.0}, pitch_deg) > 0.0)) {
    touch_y += 1e-4;
    ASSERT_LT(touch_y, 0.05) << "no anatomy above the inserted blade";
  }
  std::printf("inserted blade touches the anatomy %.1f mm higher\n",
              1e3 * (touch_y - inserted.position_m.y()));

  TissueDigest digest(setup);
  const TissueSnapshot rest = digest.make_snapshot();
  HapticLoop loop(setup);
  msg::ForceCommand command;
  msg::ContactSet contacts;
  contacts.contacts().reserve(msg::MAX_CONTACTS);
  std::uint64_t tick = 0;
  for (; tick < static_cast<std::uint64_t>(kInsertedS * 1000); ++tick) {
    const auto p = script.at(std::chrono::duration<double>(1e-3 * static_cast<double>(tick)));
    loop.tick(device_pose(tick, p.position_m, script_pitch_deg(p.orientation)), rest, command,
              contacts);
  }
  ASSERT_FALSE(command.lost_track());
  // Up to 5 mm into the palate in 0.5 s, then hold 0.5 s.
  const double start_y = inserted.position_m.y(), end_y = touch_y + 5e-3;
  for (std::uint64_t i = 0; i < 1000; ++i, ++tick) {
    const double s = std::min(1.0, static_cast<double>(i) / 500.0);
    const Eigen::Vector3d hand(inserted.position_m.x(), start_y + s * (end_y - start_y), 0.0);
    loop.tick(device_pose(tick, hand, pitch_deg), rest, command, contacts);
  }
  const Eigen::Vector3d proxy = to_eigen(command.world_from_proxy().position_m());
  const Eigen::Vector3d force = to_eigen(command.force_n());
  const double depth = anatomy_depth(setup, proxy, pitch_deg);
  std::printf("hand 5 mm into the anatomy: proxy %.2f mm into it, force (%.2f, %.2f, %.2f) N\n",
              1e3 * depth, force.x(), force.y(), force.z());
  // The proxy stops at the bone (within a fraction of the field's 1 mm grid)...
  EXPECT_LT(depth, 0.3e-3);
  EXPECT_GT(depth, -0.5e-3);
  // ...and the stylus is pushed back down, by the coupling stretched ~5 mm.
  const double k_c = setup.response.coupling.stiffness_npm;
  EXPECT_LT(force.y(), -0.8 * k_c * 5e-3);
  EXPECT_GT(force.y(), -1.2 * k_c * 5e-3);
  EXPECT_FALSE(command.lost_track());  // bone is hard, not force-aware
}

// A hostile start: the loop's first pose puts the blade inside the resting
// tongue (no approach history, so some normals point through the blade)
// and the hand then levers it up into the anatomy. Whatever the contacts
// say, the proxy must never jump (it did by 290 mm before its steps were
// bounded) and every force must be finite.
TEST(HapticLoop, EmbeddedStartStaysBounded) {
  const HapticSetup& setup = neonatal_scene().setup;
  TissueDigest digest(setup);
  TissueSnapshot rest = digest.make_snapshot();
  HapticLoop loop(setup);
  msg::ForceCommand command;
  msg::ContactSet contacts;
  contacts.contacts().reserve(msg::MAX_CONTACTS);
  Eigen::Vector3d previous_proxy = kPressTipM;
  double largest_jump = 0.0, largest_force = 0.0;
  std::uint32_t most_rows = 0;
  for (std::uint64_t tick = 0; tick < 1000; ++tick) {
    // A FEM state every 5 ticks with W for what the last tick asked for.
    if (tick % 5 == 0 && tick > 0) {
      ASSERT_TRUE(digest.digest(rest_with_compliance(setup, contacts, tick / 5), rest));
    }
    const double s = std::min(1.0, static_cast<double>(tick) / 500.0);
    const Eigen::Vector3d hand(kPressTipM.x(), kPressTipM.y() - 1e-3 + s * 9e-3, 0.0);
    loop.tick(device_pose(tick, hand, kPressPitchDeg), rest, command, contacts);
    most_rows = std::max(most_rows, loop.metrics().tool_rows.load());
    const Eigen::Vector3d proxy = to_eigen(command.world_from_proxy().position_m());
    ASSERT_TRUE(proxy.allFinite()) << "tick " << tick;
    ASSERT_TRUE(to_eigen(command.force_n()).allFinite()) << "tick " << tick;
    if (tick > 0) largest_jump = std::max(largest_jump, (proxy - previous_proxy).norm());
    largest_force = std::max(largest_force, to_eigen(command.force_n()).norm());
    previous_proxy = proxy;
  }
  std::printf("embedded start: largest proxy step %.2f mm, largest force %.2f N\n",
              1e3 * largest_jump, largest_force);
  // A tick moves the proxy by the hand's pull plus the deepest row plus
  // 1 mm at most (libs/contact); rows here are at most a few mm deep.
  EXPECT_GT(most_rows, 0u) << "no tissue row: nothing was tested";
  EXPECT_LT(largest_jump, 10e-3);
}

// The haptic loop on the neonatal scene with what a tick needs, and the
// press both tests below start with: the blade into the resting tongue over
// 200 ticks and held for 200 more, with W of 0.02 m/N for what the ticks
// ask for (a FEM state every 5 ticks, reset epoch 0). Fills every buffer.
struct PressRig {
  const HapticSetup& setup = neonatal_scene().setup;
  TissueDigest digest{setup};
  TissueSnapshot snapshot = digest.make_snapshot();
  HapticLoop loop{setup};
  msg::ForceCommand command;
  msg::ContactSet contacts;
  msg::DeformationState state;
  const Eigen::Vector3d deep{kPressTipM.x() - 0.001, kPressTipM.y() - 0.004, 0.0};
  std::uint64_t tick = 0;

  PressRig() { contacts.contacts().reserve(msg::MAX_CONTACTS); }
  // False if a state was refused.
  bool press() {
    for (; tick < 400; ++tick) {
      if (tick % 5 == 0 && tick > 0) {
        state = rest_with_compliance(setup, contacts, tick / 5);
        if (!digest.digest(state, snapshot)) return false;
      }
      const double s = std::min(1.0, static_cast<double>(tick) / 200.0);
      loop.tick(device_pose(tick, kPressTipM + s * (deep - kPressTipM), kPressPitchDeg), snapshot,
                command, contacts);
    }
    return true;
  }
};

// Presses the blade into the resting tongue for 400 ticks with W of 0.02
// m/N (FEM states every 5 ticks, reset epoch 0), then goes on for 300 ticks
// on states of `epoch` with a ten times stiffer tongue. Returns the largest
// change of the commanded force over one tick in that second part, N: over
// every tick, or (resuming_only) over the ticks whose command says it is
// slewing (FORCE_RESUMING). Once the slew has caught up the force is the
// response's: on this stiff, static tongue with the 64-row cap its rows come
// and go and it chatters by a few newtons a tick, which is not the slew's.
double largest_step_after_change(std::uint32_t epoch, std::uint64_t* resets = nullptr,
                                 bool resuming_only = false) {
  PressRig rig;
  EXPECT_TRUE(rig.press());
  const HapticSetup& setup = rig.setup;
  TissueDigest& digest = rig.digest;
  TissueSnapshot& snapshot = rig.snapshot;
  HapticLoop& loop = rig.loop;
  msg::ForceCommand& command = rig.command;
  msg::ContactSet& contacts = rig.contacts;
  const Eigen::Vector3d deep = rig.deep;
  std::uint64_t tick = rig.tick;
  Eigen::Vector3d previous = to_eigen(command.force_n());
  EXPECT_GT(previous.norm(), 0.3) << "the press made no force to change";
  double largest = 0.0;
  for (; tick < 700; ++tick) {
    if (tick % 5 == 0) {
      msg::DeformationState state = rest_with_compliance(setup, contacts, tick / 5, 0.002f);
      state.reset_epoch(epoch);
      EXPECT_TRUE(digest.digest(state, snapshot));
    }
    loop.tick(device_pose(tick, deep, kPressPitchDeg), snapshot, command, contacts);
    const Eigen::Vector3d force = to_eigen(command.force_n());
    if (!resuming_only || command.reason() == msg::FORCE_RESUMING) {
      largest = std::max(largest, (force - previous).norm());
    }
    previous = force;
  }
  if (resuming_only) {
    EXPECT_EQ(command.reason(), msg::FORCE_RENDERED) << "the slew never ended";
  }
  if (resets != nullptr) *resets = loop.metrics().tissue_resets.load();
  return largest;
}

// The FEM's W block follows the ContactSet: its rows, then the contacts
// nearest to becoming rows. The blade held where it meets the resting
// tongue, with far more contacts within the candidate margin than the block
// holds: once the FEM has answered, every contact deep enough to be a row
// has W, and a FEM state lets go of a sphere only for a deeper one. Here
// the proxy hops between two poses 0.07 mm apart as the states come, and
// two spheres trade places. Asking for the deepest contacts without W
// instead let go of the whole look-ahead (kComplianceLookAhead spheres) at
// every state, for spheres no deeper.
TEST(HapticLoop, TheWBlockKeepsItsSpheresWhileTheyStayAmongTheDeepest) {
  PressRig rig;  // its loop and buffers only: the blade stays where it meets the tongue
  HapticLoop& loop = rig.loop;
  msg::ContactSet& contacts = rig.contacts;
  std::vector<std::uint32_t> previous;
  std::vector<std::uint32_t> named;
  std::vector<std::uint32_t> gone;
  std::size_t most_gone = 0;
  int compared = 0;
  std::uint32_t fewest_contacts = std::numeric_limits<std::uint32_t>::max();
  for (std::uint64_t tick = 0; tick < 200; ++tick) {
    if (tick % 5 == 0 && tick > 0) {
      ASSERT_TRUE(
          rig.digest.digest(rest_with_compliance(rig.setup, contacts, tick / 5), rig.snapshot));
    }
    loop.tick(device_pose(tick, kPressTipM, kPressPitchDeg), rig.snapshot, rig.command, contacts);
    if (tick < 100 || tick % 5 != 4) continue;
    fewest_contacts = std::min(fewest_contacts, loop.last_phases().tissue_query.contacts);
    EXPECT_EQ(loop.metrics().missing_compliance.load(), 0u) << "tick " << tick;
    named.clear();
    for (const msg::Contact& c : contacts.contacts()) {
      if (c.kind() != msg::CONTACT_OBSTACLE) named.push_back(c.sphere_id());
    }
    std::sort(named.begin(), named.end());
    if (!previous.empty()) {
      gone.clear();
      std::set_difference(previous.begin(), previous.end(), named.begin(), named.end(),
                          std::back_inserter(gone));
      most_gone = std::max(most_gone, gone.size());
      ++compared;
    }
    previous.swap(named);
  }
  std::printf(
      "blade held at the tongue: at least %u contacts, %zu spheres named, at most %zu "
      "let go in a FEM state (%d states)\n",
      fewest_contacts, previous.size(), most_gone, compared);
  ASSERT_GT(fewest_contacts, msg::MAX_COMPLIANCE_SPHERES) << "the block holds every contact";
  EXPECT_EQ(previous.size(), msg::MAX_COMPLIANCE_SPHERES);
  EXPECT_LT(most_gone, kComplianceLookAhead / 4);
}

// Rows without W as the intubation script brings the blade to the resting
// tongue, played `speedup` times as fast, until the first tick on which the
// blade pushes on a sphere. A FEM state every 5 ticks has W for what the
// ContactSet named when the state before came, so W is one to two FEM
// periods late, as from the FEM service. Only contacts within the row
// margin are rows; the rest of the candidate margin is the block's
// look-ahead. (Past the touch this resting tongue does not give way, so
// more contacts crowd into the row margin than any block holds.)
std::uint64_t rows_without_w_until_touch(double speedup) {
  PressRig rig;           // its loop and buffers only: the script moves the blade
  msg::ContactSet asked;  // the ContactSet when the last state came
  const device::Trajectory script = device::intubation_script();
  std::uint64_t margin_ticks = 0;  // ticks with contacts within the margin
  for (std::uint64_t tick = 0; tick < 13000; ++tick) {
    if (tick % 5 == 0 && tick > 0) {
      EXPECT_TRUE(
          rig.digest.digest(rest_with_compliance(rig.setup, asked, tick / 5), rig.snapshot));
      asked = rig.contacts;
    }
    const auto p =
        script.at(std::chrono::duration<double>(1e-3 * speedup * static_cast<double>(tick)));
    rig.loop.tick(device_pose(tick, p.position_m, script_pitch_deg(p.orientation)), rig.snapshot,
                  rig.command, rig.contacts);
    const bool pushing = std::any_of(
        rig.contacts.contacts().begin(), rig.contacts.contacts().end(), [](const msg::Contact& c) {
          return c.kind() != msg::CONTACT_OBSTACLE && c.force_n() > 0.0;
        });
    if (pushing) {
      EXPECT_GT(margin_ticks, 5u) << "the blade pushed on the tongue almost as it came near";
      return rig.loop.metrics().rows_without_compliance.load();
    }
    margin_ticks += rig.loop.last_phases().tissue_query.contacts > 0 ? 1 : 0;
  }
  ADD_FAILURE() << "the blade never pushed on the tongue at " << speedup << "x";
  return 0;
}

// W arrives one or two FEM periods after a sphere is asked for; the band
// between the row margin (0.5 mm) and the candidate margin (1 mm) is asked
// for before it can be a row. At the script's pace every row has its W
// when the blade first pushes on the tongue (with rows taken within the
// whole 1 mm margin, 333 contact-ticks had none); eight times as fast, the
// blade outruns the band: the check can fail.
TEST(HapticLoop, TheLookAheadBandGivesEveryRowItsWOnAnApproach) {
  const std::uint64_t paced = rows_without_w_until_touch(1.0);
  const std::uint64_t fast = rows_without_w_until_touch(8.0);
  std::printf("rows without W until the blade pushes: %llu at the script's pace, %llu at 8x\n",
              static_cast<unsigned long long>(paced), static_cast<unsigned long long>(fast));
  EXPECT_EQ(paced, 0u);
  EXPECT_GT(fast, 0u) << "the fast approach found W everywhere: nothing was tested";
}

// A tongue that jumped (a new reset epoch) is not rendered as it jumped:
// the force changes by at most 0.1 N a tick until it matches what the new
// state gives. The same stiffer tongue without a new epoch is the control:
// its force does step by more, so the bound is the slew's doing.
TEST(HapticLoop, ANewResetEpochSlewsTheForce) {
  std::uint64_t resets = 0;
  const double with_epoch = largest_step_after_change(1, &resets, true);
  const double control = largest_step_after_change(0);
  std::printf("largest force change a tick: %.3f N after a reset epoch, %.3f N without\n",
              with_epoch, control);
  EXPECT_EQ(resets, 1u);
  EXPECT_GT(control, kResetSlewN) << "the stiffer tongue made no step to bound";
  EXPECT_LE(with_epoch, kResetSlewN + 1e-9);
}

// The FEM lost mid-press: the tongue is not rendered, the force ramps to
// zero within the ramp (150 servo ticks), at most 0.1 N a tick, with no
// local stiffness, each command saying why; the ContactSet repeats the
// press's contacts (a late FEM keeps the tongue under the blade). When a
// state comes again the force resumes through the reset slew.
TEST(HapticLoop, ALostTissueRampsTheForceToZeroAndResumesThroughTheSlew) {
  PressRig rig;
  ASSERT_TRUE(rig.press());
  HapticLoop& loop = rig.loop;
  Eigen::Vector3d previous = to_eigen(rig.command.force_n());
  ASSERT_GT(previous.norm(), 0.3) << "the press made no force to ramp";
  std::uint64_t tick = rig.tick;
  double largest = 0.0;
  std::uint64_t zero_after = 0;
  std::vector<std::uint32_t> pressed;
  for (const msg::Contact& c : rig.contacts.contacts()) {
    if (c.kind() == msg::CONTACT_TOOL && c.state() != msg::CONSTRAINT_CANDIDATE)
      pressed.push_back(c.sphere_id());
  }
  ASSERT_FALSE(pressed.empty());
  for (std::uint64_t i = 0; i < 200; ++i, ++tick) {
    rig.contacts.contacts().clear();  // a publisher's other slot
    loop.tick(device_pose(tick, rig.deep, kPressPitchDeg), rig.snapshot, rig.command, rig.contacts,
              true);
    const Eigen::Vector3d force = to_eigen(rig.command.force_n());
    largest = std::max(largest, (force - previous).norm());
    previous = force;
    EXPECT_EQ(rig.command.reason(), msg::FORCE_TISSUE_LOST);
    std::vector<std::uint32_t> sent;
    for (const msg::Contact& c : rig.contacts.contacts()) {
      if (c.kind() == msg::CONTACT_TOOL && c.state() != msg::CONSTRAINT_CANDIDATE)
        sent.push_back(c.sphere_id());
    }
    EXPECT_EQ(sent, pressed) << "lost tick " << i;
    for (const double k : rig.command.stiffness_npm().m()) EXPECT_EQ(k, 0.0);
    if (zero_after == 0 && force.norm() == 0.0) zero_after = i + 1;
  }
  std::printf("tissue lost: zero after %llu ticks, largest step %.3f N\n",
              static_cast<unsigned long long>(zero_after), largest);
  EXPECT_LE(largest, kResetSlewN + 1e-9);
  EXPECT_GT(zero_after, 100u);
  EXPECT_LE(zero_after, static_cast<std::uint64_t>(kLossRampTicks));
  EXPECT_EQ(loop.metrics().tissue_losses.load(), 1u);
  // States again: the force climbs back at most 0.1 N a tick while it
  // slews (saying so); after that it is the response's.
  largest = 0.0;
  bool resumed = false;
  double peak = 0.0;
  for (std::uint64_t i = 0; i < 300; ++i, ++tick) {
    if (tick % 5 == 0) {
      rig.state = rest_with_compliance(rig.setup, rig.contacts, tick / 5);
      ASSERT_TRUE(rig.digest.digest(rig.state, rig.snapshot));
    }
    loop.tick(device_pose(tick, rig.deep, kPressPitchDeg), rig.snapshot, rig.command, rig.contacts);
    const Eigen::Vector3d force = to_eigen(rig.command.force_n());
    if (rig.command.reason() == msg::FORCE_RESUMING) {
      largest = std::max(largest, (force - previous).norm());
      resumed = true;
    }
    peak = std::max(peak, force.norm());
    previous = force;
  }
  EXPECT_TRUE(resumed);
  EXPECT_EQ(rig.command.reason(), msg::FORCE_RENDERED);
  EXPECT_GT(peak, 0.3) << "the force did not come back";
  EXPECT_LE(largest, kResetSlewN + 1e-9);
  EXPECT_EQ(loop.metrics().tissue_returns.load(), 1u);
}

// A restarted FEM service is a new writer whose tongue starts at rest and
// whose epochs count from 0 again: the same slew as a new reset epoch.
TEST(HapticLoop, ANewFemWriterResumesThroughTheSlew) {
  PressRig rig;
  // The press on states of writer 7.
  for (; rig.tick < 400; ++rig.tick) {
    if (rig.tick % 5 == 0 && rig.tick > 0) {
      rig.state = rest_with_compliance(rig.setup, rig.contacts, rig.tick / 5);
      rig.state.header().writer_id(7);
      ASSERT_TRUE(rig.digest.digest(rig.state, rig.snapshot));
    }
    const double s = std::min(1.0, static_cast<double>(rig.tick) / 200.0);
    rig.loop.tick(device_pose(rig.tick, kPressTipM + s * (rig.deep - kPressTipM), kPressPitchDeg),
                  rig.snapshot, rig.command, rig.contacts);
  }
  Eigen::Vector3d previous = to_eigen(rig.command.force_n());
  ASSERT_GT(previous.norm(), 0.3);
  double largest = 0.0;
  bool resumed = false;
  for (std::uint64_t tick = rig.tick; tick < 700; ++tick) {
    if (tick % 5 == 0) {
      // Writer 9, a stiffer tongue, its steps and epoch from 0.
      rig.state = rest_with_compliance(rig.setup, rig.contacts, (tick - 400) / 5, 0.002f);
      rig.state.header().writer_id(9);
      ASSERT_TRUE(rig.digest.digest(rig.state, rig.snapshot));
    }
    rig.loop.tick(device_pose(tick, rig.deep, kPressPitchDeg), rig.snapshot, rig.command,
                  rig.contacts);
    const Eigen::Vector3d force = to_eigen(rig.command.force_n());
    // While it slews (after that the force is the response's: see
    // largest_step_after_change).
    if (rig.command.reason() == msg::FORCE_RESUMING) {
      largest = std::max(largest, (force - previous).norm());
      resumed = true;
    }
    previous = force;
  }
  EXPECT_TRUE(resumed);
  EXPECT_EQ(rig.command.reason(), msg::FORCE_RENDERED);
  EXPECT_EQ(rig.loop.metrics().fem_writers.load(), 1u);
  EXPECT_LE(largest, kResetSlewN + 1e-9);
}

// A device that renders nothing (disabled or engaging) gets zero force and
// no stiffness, so it can engage while the blade presses; once it renders,
// the force climbs from zero at most 0.1 N a tick.
TEST(HapticLoop, AnIdleDeviceGetsZeroThenTheSlew) {
  PressRig rig;
  ASSERT_TRUE(rig.press());
  std::uint64_t tick = rig.tick;
  for (int i = 0; i < 60; ++i, ++tick) {
    msg::DevicePose pose = device_pose(tick, rig.deep, kPressPitchDeg);
    pose.safety_state(msg::DEVICE_ENGAGING);
    rig.loop.tick(pose, rig.snapshot, rig.command, rig.contacts);
    EXPECT_EQ(to_eigen(rig.command.force_n()).norm(), 0.0);
    EXPECT_EQ(rig.command.reason(), msg::FORCE_DEVICE_NOT_ENABLED);
  }
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  double largest = 0.0;
  for (int i = 0; i < 200; ++i, ++tick) {
    if (tick % 5 == 0) {
      rig.state = rest_with_compliance(rig.setup, rig.contacts, tick / 5);
      ASSERT_TRUE(rig.digest.digest(rig.state, rig.snapshot));
    }
    rig.loop.tick(device_pose(tick, rig.deep, kPressPitchDeg), rig.snapshot, rig.command,
                  rig.contacts);
    const Eigen::Vector3d force = to_eigen(rig.command.force_n());
    largest = std::max(largest, (force - previous).norm());
    previous = force;
  }
  EXPECT_GT(previous.norm(), 0.3);
  EXPECT_LE(largest, kResetSlewN + 1e-9);
}

#ifndef FAHR_SANITIZE_BUILD
TEST(HapticLoop, TickAndDigestAllocateNothing) {
  PressRig rig;
  ASSERT_TRUE(rig.press());
  TissueDigest& digest = rig.digest;
  TissueSnapshot& snapshot = rig.snapshot;
  HapticLoop& loop = rig.loop;
  msg::ForceCommand& command = rig.command;
  msg::ContactSet& contacts = rig.contacts;
  msg::DeformationState& state = rig.state;
  const Eigen::Vector3d deep = rig.deep;
  std::uint64_t tick = rig.tick;
  ASSERT_GT(loop.metrics().tool_rows.load(), 0u) << "the blade does not touch the tongue";
  state.step(state.step() + 1);
  ASSERT_TRUE(digest.digest(state, snapshot));
  fahr::test::AllocationCounter counter;
  for (int i = 0; i < 200; ++i, ++tick) {
    if (i % 5 == 0) {
      state.step(state.step() + 1);
      ASSERT_TRUE(digest.digest(state, snapshot));
    }
    loop.tick(device_pose(tick, deep, kPressPitchDeg), snapshot, command, contacts);
  }
  EXPECT_EQ(counter.count(), 0);
  EXPECT_GT(contacts.contacts().size(), 0u);
}
#endif

TEST(TissueDigest, RefusesStatesThatDoNotFit) {
  const HapticSetup& setup = neonatal_scene().setup;
  TissueDigest digest(setup);
  TissueSnapshot snapshot = digest.make_snapshot();
  msg::DeformationState state;
  state.body_id(setup.bodies.front().body->id);
  state.positions_m().assign(3 * setup.mesh.node_count() - 3, 0.0f);
  EXPECT_FALSE(digest.digest(state, snapshot));
  for (const Eigen::Vector3d& x : setup.mesh.rest_positions()) {
    for (int a = 0; a < 3; ++a) state.positions_m().push_back(static_cast<float>(x[a]));
  }
  const auto stale = static_cast<std::ptrdiff_t>(3 * setup.mesh.node_count() - 3);
  state.positions_m().erase(state.positions_m().begin(), state.positions_m().begin() + stale);
  ASSERT_EQ(state.positions_m().size(), 3 * setup.mesh.node_count());
  EXPECT_TRUE(digest.digest(state, snapshot));
  state.positions_m()[7] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(digest.digest(state, snapshot));
  state.positions_m()[7] = static_cast<float>(setup.mesh.rest_positions()[2].y());
  ASSERT_TRUE(digest.digest(state, snapshot));
  // The state of a body the scene does not have (its key another id).
  state.body_id(state.body_id() + 1);
  EXPECT_FALSE(digest.plausible(state));
  EXPECT_FALSE(digest.digest(state, snapshot));
  state.body_id(setup.bodies.front().body->id);
  // A non-finite W, W normal or free centre: the state is refused whole.
  state.compliance_sphere_ids().assign({3, 4});
  state.compliance_mpn().assign(21, 0.01f);  // the upper triangle of 6 x 6
  ASSERT_TRUE(digest.digest(state, snapshot));
  state.compliance_mpn()[17] = std::numeric_limits<float>::infinity();
  EXPECT_FALSE(digest.digest(state, snapshot));
  state.compliance_mpn()[17] = 0.01f;
  state.compliance_free_centres_m().assign(6, 0.0f);
  state.compliance_free_centres_m()[4] = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(digest.digest(state, snapshot));
  state.compliance_free_centres_m().clear();
  state.compliance_normals().assign(6, std::numeric_limits<float>::quiet_NaN());
  state.compliance_mpn().assign(12, 0.01f);
  EXPECT_FALSE(digest.digest(state, snapshot));
}

// The neonatal scene's digest, a fresh snapshot and a state at rest.
class TissueDigestAtRest : public ::testing::Test {
 protected:
  const HapticSetup& setup_ = neonatal_scene().setup;
  TissueDigest digest_{setup_};
  TissueSnapshot snapshot_ = digest_.make_snapshot();
  msg::DeformationState state_ = rest_state(setup_);
};

TEST_F(TissueDigestAtRest, IndexesTheComplianceSpheres) {
  state_.compliance_sphere_ids({5, 9});
  state_.compliance_mpn().assign(21, 1e-3f);
  state_.compliance_free_centres_m().assign(6, 0.01f);
  ASSERT_TRUE(digest_.digest(state_, snapshot_));
  EXPECT_EQ(snapshot_.compliance_index[5], 0);
  EXPECT_EQ(snapshot_.compliance_index[9], 1);
  EXPECT_EQ(snapshot_.compliance_index[6], contact::kNoCompliance);
  EXPECT_TRUE(snapshot_.have_free_centres);
  // The next state in the same slot forgets the old spheres.
  state_.compliance_sphere_ids({6});
  state_.compliance_mpn().assign(6, 1e-3f);
  state_.compliance_free_centres_m().clear();
  ASSERT_TRUE(digest_.digest(state_, snapshot_));
  EXPECT_EQ(snapshot_.compliance_index[5], contact::kNoCompliance);
  EXPECT_EQ(snapshot_.compliance_index[6], 0);
  EXPECT_FALSE(snapshot_.have_free_centres);
  // An id beyond the layout refuses the whole W.
  state_.compliance_sphere_ids({static_cast<std::uint32_t>(setup_.layout.size())});
  ASSERT_TRUE(digest_.digest(state_, snapshot_));
  EXPECT_EQ(snapshot_.compliance_count, 0u);
}

// 3x3 blocks arrive as the upper triangle of W: the digest gives the tick
// the whole matrix, each entry below the diagonal the one above it.
TEST_F(TissueDigestAtRest, UnpacksWsUpperTriangle) {
  state_.compliance_sphere_ids({5, 9});
  const std::size_t n = 6;
  state_.compliance_mpn().resize(common::packed_upper_size(n));
  for (std::size_t r = 0; r < n; ++r) {
    for (std::size_t c = r; c < n; ++c)  // distinct values, diagonal largest
      state_.compliance_mpn()[common::packed_upper_index(n, r, c)] =
          r == c ? 1e-2f : 1e-4f * static_cast<float>(1 + r * n + c);
  }
  ASSERT_TRUE(digest_.digest(state_, snapshot_));
  const contact::TissueCompliance w = snapshot_.compliance();
  ASSERT_TRUE(w.valid());
  ASSERT_FALSE(w.along_normals());
  const Eigen::Vector3d axis[3] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                   Eigen::Vector3d::UnitZ()};
  for (std::size_t r = 0; r < n; ++r) {
    for (std::size_t c = 0; c < n; ++c) {
      const float expected =
          state_.compliance_mpn()[common::packed_upper_index(n, std::min(r, c), std::max(r, c))];
      EXPECT_NEAR(w.normal_compliance(r / 3, axis[r % 3], c / 3, axis[c % 3]), expected, 1e-9)
          << "entry (" << r << ", " << c << ")";
    }
  }
}

// What the FEM sends of a W whose columns came from two factorisations
// (not quite symmetric): the tick gets its symmetric part.
TEST(PackedSymmetric, PackThenUnpackGivesTheSymmetricPart) {
  constexpr std::size_t kN = 5;
  std::array<float, kN * kN> full{};
  for (std::size_t i = 0; i < kN * kN; ++i) full.at(i) = 0.25f * static_cast<float>(i * i % 17);
  std::array<float, common::packed_upper_size(kN)> packed{};
  common::pack_upper(full.data(), kN, packed.data());
  std::array<float, kN * kN> back{};
  common::unpack_upper(packed.data(), kN, back.data(), kN);
  for (std::size_t i = 0; i < kN; ++i) {
    for (std::size_t j = 0; j < kN; ++j)
      EXPECT_FLOAT_EQ(back.at(i * kN + j), 0.5f * (full.at(i * kN + j) + full.at(j * kN + i)));
  }
}

TEST_F(TissueDigestAtRest, TakesWAlongTheFemsNormals) {
  // (3k x k) columns with k normals: the view reads them as W along the
  // normals; without enough normals, or with a block of the 3x3 size but
  // normals present, W is refused (rows then use the fallback).
  state_.compliance_sphere_ids({5, 9});
  state_.compliance_mpn().assign(12, 0.0f);
  state_.compliance_mpn()[(3 * 1 + 1) * 2 + 0] =
      2e-3f;  // sphere 9 moves +y per newton on sphere 5 along its normal
  state_.compliance_normals({0.0f, 1.0f, 0.0f, 1.0f, 0.0f, 0.0f});
  ASSERT_TRUE(digest_.digest(state_, snapshot_));
  ASSERT_EQ(snapshot_.compliance_count, 2u);
  const contact::TissueCompliance w = snapshot_.compliance();
  ASSERT_TRUE(w.valid());
  ASSERT_TRUE(w.along_normals());
  EXPECT_NEAR(w.normal_compliance(1, Eigen::Vector3d::UnitY(), 0, Eigen::Vector3d::UnitY()), 2e-3,
              1e-9);
  EXPECT_NEAR(w.normal_compliance(1, Eigen::Vector3d::UnitY(), 0, -Eigen::Vector3d::UnitY()), -2e-3,
              1e-9);
  state_.compliance_normals().pop_back();
  ASSERT_TRUE(digest_.digest(state_, snapshot_));
  EXPECT_EQ(snapshot_.compliance_count, 0u);
  // Back to 3x3 blocks: no normals, the 6 x 6 block's upper triangle.
  state_.compliance_normals().clear();
  state_.compliance_mpn().assign(21, 1e-3f);
  ASSERT_TRUE(digest_.digest(state_, snapshot_));
  EXPECT_EQ(snapshot_.compliance_count, 2u);
  EXPECT_FALSE(snapshot_.compliance().along_normals());
}

}  // namespace
}  // namespace fahr::haptic_service::test
