// The device gateway in lockstep over DDS: a coordinator in this process
// grants 2,000 base steps to a fahr_device_gateway process running the
// simulated intubation with no haptic service (no ForceCommand input); the
// DevicePose stream's hash (reported in the
// gateway's StepAck) is the same on every run and on both vendors.
#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "fahr/common/lockstep.h"
#include "subprocess.h"

namespace fahr::test {
namespace {

using namespace std::chrono_literals;

std::uint64_t run_gateway(common::Vendor vendor, std::uint32_t domain) {
  Subprocess gateway({FAHR_GATEWAY, "--mode", "lockstep", "--dds",
                      std::string(common::vendor_name(vendor)), "--domain", std::to_string(domain),
                      "--backend", "simulated", "--script", "intubation", "--duration-s", "0",
                      "--force-input-period", "0"});
  common::TransportConfig config;
  config.vendor = vendor;
  config.domain_id = domain;
  common::Participant participant(config);
  common::LockstepCoordinator coordinator(participant, 1ms);
  const auto result = coordinator.run({"device_gateway"}, 2000, 30s);
  EXPECT_TRUE(result.completed) << "stalled at step " << result.steps;
  EXPECT_EQ(gateway.wait(20000), 0);
  return result.hashes.count("device_gateway") != 0 ? result.hashes.at("device_gateway") : 0;
}

TEST(GatewayLockstep, SimulatedIntubationGivesTheSameDevicePoseStream) {
  const std::uint64_t first = run_gateway(common::Vendor::kFastDds, 71);
  const std::uint64_t second = run_gateway(common::Vendor::kFastDds, 72);
  const std::uint64_t cyclone = run_gateway(common::Vendor::kCyclone, 73);
  EXPECT_NE(first, 0U);
  EXPECT_EQ(first, second);
  EXPECT_EQ(first, cyclone);
  std::printf("gateway lockstep DevicePose hash %016llx\n", static_cast<unsigned long long>(first));
}

}  // namespace
}  // namespace fahr::test
