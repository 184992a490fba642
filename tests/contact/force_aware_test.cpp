// The force-aware decision on a synthetic patch: freeze past the limit,
// hold, release with hysteresis, catch up without a force step.
#include <gtest/gtest.h>

#include "fahr/contact/contact_response.h"
#include "synthetic.h"

namespace fahr::contact {
namespace {

struct Trace {
  bool froze = false, released = false, tracking_again = false;
  double max_reaction_lost = 0.0, max_step = 0.0;
  Eigen::Vector3d frozen_proxy = Eigen::Vector3d::Zero();
  double proxy_drift_lost = 0.0;
  int frozen_contacts = 0;
};

// Device down at 10 mm/s to `bottom`, then back up; rows follow the proxy.
Trace press(ContactResponse& response, test::SyntheticPatch& patch, double limit, double bottom) {
  Trace trace;
  double y = 0.002;
  bool down = true;
  Eigen::Vector3d previous_force = Eigen::Vector3d::Zero();
  bool was_lost = false;
  for (int k = 0; k < 4000; ++k) {
    if (down && y <= bottom) down = false;
    y += down ? -1e-5 : 1e-5;
    test::set_tool_height(patch, response.proxy().position_m.y());
    TickInput in;
    in.device.position_m = Eigen::Vector3d(0, y, 0);
    in.device.velocity_mps = Eigen::Vector3d(0, down ? -0.01 : 0.01, 0);
    in.device.renderable_force_n = limit;
    in.rows = patch.rows;
    in.compliance = patch.compliance();
    const ForceOutput& out = response.tick(in);
    if (out.lost_track) {
      if (!was_lost) trace.frozen_proxy = out.proxy_position_m;
      trace.froze = true;
      trace.max_reaction_lost = std::max(trace.max_reaction_lost, out.tissue_reaction_n);
      trace.proxy_drift_lost = std::max(trace.proxy_drift_lost, (out.proxy_position_m - trace.frozen_proxy).norm());
      int frozen = 0;
      for (const fem::Contact& c : response.contacts()) frozen += c.state == fem::ContactState::kFrozen;
      trace.frozen_contacts = std::max(trace.frozen_contacts, frozen);
    }
    if (was_lost && !out.lost_track) trace.released = true;
    if (trace.released && response.state() == TrackingState::kTracking) trace.tracking_again = true;
    if (k > 0) trace.max_step = std::max(trace.max_step, (out.force_n - previous_force).norm());
    previous_force = out.force_n;
    was_lost = out.lost_track;
  }
  return trace;
}

TEST(ForceAware, FreezesPastTheLimitHoldsAndCatchesUpSmoothly) {
  test::SyntheticPatch patch = test::make_patch(4, 0.0, 0.002, 0.005);
  ResponseSettings settings;
  ContactResponse response(settings);
  response.reset(Eigen::Vector3d(0, 0.002, 0), Eigen::Quaterniond::Identity());
  const double limit = 0.5;
  const Trace t = press(response, patch, limit, -0.012);
  EXPECT_TRUE(t.froze);
  EXPECT_TRUE(t.released);
  EXPECT_TRUE(t.tracking_again);
  EXPECT_LE(t.max_reaction_lost, 1.05 * limit);
  EXPECT_EQ(t.proxy_drift_lost, 0.0);
  EXPECT_EQ(t.frozen_contacts, 4);
  // Bound (README): K_c (|dx_d| + v_c dt) + B (|dv_d| + v_c); the device's
  // turn-around changes v_d by 0.02 m/s in one tick.
  const double bound = 400.0 * (1e-5 + 0.05 * 0.001) + 1.0 * (0.02 + 0.05);
  EXPECT_LE(t.max_step, bound);
}

TEST(ForceAware, DisabledNeverFreezes) {
  test::SyntheticPatch patch = test::make_patch(4, 0.0, 0.002, 0.005);
  ResponseSettings settings;
  settings.force_aware.enabled = false;
  ContactResponse response(settings);
  response.reset(Eigen::Vector3d(0, 0.002, 0), Eigen::Quaterniond::Identity());
  EXPECT_FALSE(press(response, patch, 0.5, -0.012).froze);
}

}  // namespace
}  // namespace fahr::contact
