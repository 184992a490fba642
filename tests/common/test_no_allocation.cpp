// The 1 kHz side of the transport allocates nothing: taking the newest
// sample (any vendor) and writing on the in-process bus, after warm-up.
// Allocations are counted per thread by replacing global operator new, so
// the vendors' own threads do not count against the loop under test.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <new>
#include <thread>

#include "allocation_counter.h"
#include "fahr/common/publisher.h"
#include "fahr/common/subscriber.h"
#include "sample_factory.h"

namespace fahr::test {
namespace {

using namespace std::chrono_literals;

TEST(NoAllocation, InProcessWriteAndTakeNewest) {
  common::TransportConfig config;
  config.vendor = common::Vendor::kInProcess;
  config.domain_id = 50;
  common::Participant participant(config);
  common::Publisher<msg::DeformationState> pub(participant);
  common::Subscriber<msg::DeformationState> sub(participant);
  msg::DeformationState state;
  fill(state, 1, 2000);
  for (int i = 0; i < 10; ++i) {  // warm-up: every slot reaches its size
    pub.write(state);
    sub.fetch_newest();
  }
  AllocationCounter counter;
  double sum = 0;
  for (int i = 0; i < 1000; ++i) {
    state.step(static_cast<std::uint64_t>(i));
    pub.write(state);
    if (sub.fetch_newest()) sum += sub.newest().positions_m()[0];
  }
  EXPECT_EQ(counter.count(), 0);
  EXPECT_NE(sum, 0.0);
}

class VendorNoAllocation : public testing::TestWithParam<common::Vendor> {};

TEST_P(VendorNoAllocation, TakingTheNewestSampleAllocatesNothing) {
  common::TransportConfig config;
  config.vendor = GetParam();
  config.domain_id = 51 + static_cast<std::uint32_t>(GetParam());
  common::Participant participant(config);
  common::Publisher<msg::DevicePose> pub(participant);
  common::Subscriber<msg::DevicePose> sub(participant);
  msg::DevicePose pose;
  std::thread writer([&] {
    for (int i = 0; i < 600; ++i) {
      pose.servo_tick(static_cast<std::uint64_t>(i));
      pub.write(pose);
      std::this_thread::sleep_for(500us);
    }
  });
  // Warm-up, then a loop like the haptic tick's: poll, read, never block.
  while (sub.received() < 20) std::this_thread::sleep_for(1ms);
  sub.fetch_newest();
  long taken = 0;
  {
    AllocationCounter counter;
    for (int i = 0; i < 200; ++i) {
      if (sub.fetch_newest()) taken += static_cast<long>(sub.newest().servo_tick() > 0);
      std::this_thread::sleep_for(1ms);
    }
    EXPECT_EQ(counter.count(), 0);
  }
  writer.join();
  EXPECT_GT(taken, 50);
}

INSTANTIATE_TEST_SUITE_P(Vendors, VendorNoAllocation,
                         testing::Values(common::Vendor::kFastDds, common::Vendor::kCyclone),
                         [](const testing::TestParamInfo<common::Vendor>& param) {
                           return std::string(common::vendor_name(param.param));
                         });

}  // namespace
}  // namespace fahr::test
