// Lockstep determinism: a 1 kHz and a 100 Hz participant in separate
// processes produce bit-identical output hashes over repeated runs, with
// and without timing jitter, on Fast DDS, on Cyclone DDS and mixed, and the
// same hashes as the in-process bus.
#include <gtest/gtest.h>

#include <future>
#include <map>

#include "fahr/common/lockstep.h"
#include "lockstep_scenario.h"
#include "subprocess.h"

namespace fahr::test {
namespace {

using common::Vendor;
using namespace std::chrono_literals;

constexpr std::uint64_t kSteps = 2000;  // 2 s of simulated time at 1 ms

TEST(ReadRule, NewestProducerStepStrictlyBefore) {
  EXPECT_FALSE(common::producer_step_for(0, 10).has_value());
  EXPECT_EQ(*common::producer_step_for(1, 10), 0U);
  EXPECT_EQ(*common::producer_step_for(10, 10), 0U);
  EXPECT_EQ(*common::producer_step_for(11, 10), 10U);
  EXPECT_EQ(*common::producer_step_for(7, 1), 6U);
}

std::map<std::string, std::uint64_t> run_processes(Vendor coordinator_vendor, Vendor fast_vendor,
                                                   Vendor slow_vendor, std::uint32_t domain,
                                                   std::uint32_t jitter_seed) {
  const std::string peer = executable_dir() + "/lockstep_peer";
  Subprocess fast({peer, "fast", std::string(common::vendor_name(fast_vendor)),
                   std::to_string(domain), std::to_string(jitter_seed)});
  Subprocess slow({peer, "slow", std::string(common::vendor_name(slow_vendor)),
                   std::to_string(domain),
                   std::to_string(jitter_seed + (jitter_seed != 0 ? 1 : 0))});
  common::TransportConfig config;
  config.vendor = coordinator_vendor;
  config.domain_id = domain;
  config.participant_name = "lockstep_coordinator";
  common::Participant participant(config);
  common::LockstepCoordinator coordinator(participant, 1ms);
  const auto result = coordinator.run({"fast", "slow"}, kSteps, 20s);
  EXPECT_TRUE(result.completed) << "stalled at step " << result.steps;
  EXPECT_EQ(fast.wait(20000), 0);
  EXPECT_EQ(slow.wait(20000), 0);
  return result.hashes;
}

std::map<std::string, std::uint64_t> run_in_process(std::uint32_t jitter_seed, double pace = 0.0) {
  common::TransportConfig config;
  config.vendor = Vendor::kInProcess;
  config.domain_id = 40 + jitter_seed;
  common::Participant coordinator_participant(config);
  common::Participant fast_participant(config);
  common::Participant slow_participant(config);
  common::LockstepCoordinator coordinator(coordinator_participant, 1ms);
  auto fast = std::async(std::launch::async, [&] {
    return run_lockstep_participant(fast_participant, "fast", jitter_seed);
  });
  auto slow = std::async(std::launch::async, [&] {
    return run_lockstep_participant(slow_participant, "slow", jitter_seed);
  });
  const auto result = coordinator.run({"fast", "slow"}, kSteps, 20s, pace);
  EXPECT_TRUE(result.completed);
  EXPECT_EQ(fast.get(), result.hashes.at("fast"));
  EXPECT_EQ(slow.get(), result.hashes.at("slow"));
  return result.hashes;
}

TEST(Lockstep, HashesAreBitIdenticalAcrossRunsAndVendors) {
  const auto reference = run_in_process(0);
  ASSERT_EQ(reference.size(), 2U);
  EXPECT_EQ(run_in_process(7), reference) << "in-process run with jitter";

  struct Run {
    const char* name;
    Vendor coordinator, fast, slow;
    std::uint32_t jitter;
  };
  const Run runs[] = {
      {"fastdds", Vendor::kFastDds, Vendor::kFastDds, Vendor::kFastDds, 0},
      {"fastdds+jitter", Vendor::kFastDds, Vendor::kFastDds, Vendor::kFastDds, 11},
      {"cyclonedds", Vendor::kCyclone, Vendor::kCyclone, Vendor::kCyclone, 0},
      {"cyclonedds+jitter", Vendor::kCyclone, Vendor::kCyclone, Vendor::kCyclone, 13},
      {"mixed", Vendor::kFastDds, Vendor::kFastDds, Vendor::kCyclone, 0},
      {"mixed+jitter", Vendor::kCyclone, Vendor::kCyclone, Vendor::kFastDds, 17},
  };
  std::uint32_t domain = 30;
  for (const auto& run : runs) {
    SCOPED_TRACE(run.name);
    const auto hashes = run_processes(run.coordinator, run.fast, run.slow, domain++, run.jitter);
    EXPECT_EQ(hashes, reference);
    std::printf("lockstep %-18s fast %016llx slow %016llx\n", run.name,
                static_cast<unsigned long long>(hashes.count("fast") ? hashes.at("fast") : 0),
                static_cast<unsigned long long>(hashes.count("slow") ? hashes.at("slow") : 0));
  }
}

// --pace for a viewer: step k is granted no earlier than k base periods /
// pace after step 0, so 2000 steps of 1 ms at pace 2 take at least 1 s of
// wall time (unpaced, the in-process run takes a few tens of ms); pacing
// only delays grants, so the hashes are the unpaced run's.
TEST(Lockstep, PaceHoldsSimulatedTimeToAMultipleOfWallTime) {
  const auto start = std::chrono::steady_clock::now();
  const auto unpaced = run_in_process(0);
  const double unpaced_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto paced_start = std::chrono::steady_clock::now();
  const auto paced = run_in_process(0, 2.0);
  const double paced_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - paced_start).count();
  std::printf("lockstep %llu steps of 1 ms: unpaced %.3f s, at pace 2 %.3f s wall\n",
              static_cast<unsigned long long>(kSteps), unpaced_s, paced_s);
  const double floor_s = static_cast<double>(kSteps - 1) * 1e-3 / 2.0;
  EXPECT_GE(paced_s, floor_s);
  EXPECT_EQ(paced, unpaced);
}

}  // namespace
}  // namespace fahr::test
