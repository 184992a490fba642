// The tick allocates nothing once constructed (counting operator new).
#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "fahr/contact/contact_response.h"
#include "fahr/contact/penalty_response.h"
#include "synthetic.h"

namespace fahr::contact {
namespace {

TEST(Allocation, ContactResponseTickAllocatesNothing) {
  test::SyntheticPatch patch = test::make_patch(24, 0.0, 0.002, 0.002);
  ContactResponse response(ResponseSettings{});
  response.reset(Eigen::Vector3d(0, 0.001, 0), Eigen::Quaterniond::Identity());
  TickInput in;
  in.rows = patch.rows;
  in.compliance = patch.compliance();
  in.device.renderable_force_n = 0.5;
  double y = 0.001;
  fahr::test::AllocationCounter counter;
  // Down past the limit (freeze), back up (release, catch-up): every branch.
  for (int k = 0; k < 3000; ++k) {
    y += k < 1500 ? -1e-5 : 1e-5;
    test::set_tool_height(patch, response.proxy().position_m.y());
    in.device.position_m = Eigen::Vector3d(0, y, 0);
    response.tick(in);
  }
  EXPECT_EQ(counter.count(), 0);
}

TEST(Allocation, PenaltyTickAllocatesNothing) {
  test::SyntheticPatch patch = test::make_patch(24, -0.001, 0.002, 0.002);
  PenaltyResponse penalty(PenaltySettings{});
  DeviceSample device;
  fahr::test::AllocationCounter counter;
  for (int k = 0; k < 100; ++k) penalty.tick(device, patch.rows, 1);
  EXPECT_EQ(counter.count(), 0);
}

}  // namespace
}  // namespace fahr::contact
