// The servo tick allocates nothing: global operator new is replaced to count
// allocations on this thread while ticks run (after set-up), with every
// back-end the library has and hostile commands mixed in.
#include <gtest/gtest.h>

#include <cstdlib>
#include <limits>
#include <new>

#include "allocation_counter.h"
#include "fahr/device/remote_input_backend.h"
#include "fahr/device/replay_backend.h"
#include "fahr/device/simulated_backend.h"
#include "test_support.h"

namespace fahr::test {
namespace {

// Commands of every kind the safety layer handles: good, huge, NaN, stale.
device::ForceCommandSample hostile(std::uint64_t tick, const Vec3& position_m) {
  device::ForceCommandSample c;
  c.answered_pose_seq = tick;
  c.answered_position_m = position_m;
  c.force_n = Vec3(0.0, 0.2, 0.0);
  c.stiffness_npm(1, 1) = 800.0;
  switch (tick % 5) {
    case 1:
      c.force_n *= 1e12;
      break;
    case 2:
      c.force_n.x() = std::numeric_limits<double>::quiet_NaN();
      break;
    case 3:
      c.answered_pose_seq = tick > 100 ? tick - 100 : 0;
      break;
    default:
      break;
  }
  return c;
}

void run_ticks(device::ServoCore& core, std::uint64_t first, std::uint64_t count,
               const Vec3& position_m) {
  for (std::uint64_t t = first; t < first + count; ++t) {
    const device::ForceCommandSample c = hostile(t, position_m);
    core.tick(tick_time(t), t > 0 ? &c : nullptr);
  }
}

TEST(NoAllocation, SimulatedServoTick) {
  device::GatewayConfig config;
  device::SimulatedBackend backend(device::intubation_script(), device::HandImpedance{},
                                   config.model, config.mapping, config.period);
  device::ServoCore core(config, backend);
  run_ticks(core, 0, 100, Vec3::Zero());  // warm-up
  AllocationCounter counter;
  run_ticks(core, 100, 13'000, Vec3(0.0, -1e-3, 0.0));
  EXPECT_EQ(counter.count(), 0);
  EXPECT_GT(core.safety_counters().rejected_non_finite, 0U);
  EXPECT_GT(core.latency().count(), 0U);
}

TEST(NoAllocation, ReplayAndRemoteServoTicks) {
  device::GatewayConfig config;
  device::Recording recording;
  recording.samples.resize(2000);
  for (std::size_t i = 0; i < recording.samples.size(); ++i) {
    recording.samples[i].device_time_ns = static_cast<std::int64_t>(i) * 1'000'000;
  }
  device::ReplayBackend replay(std::move(recording));
  device::ServoCore replay_core(config, replay);
  device::RemoteInputBackend remote(config.model);
  device::ServoCore remote_core(config, remote);
  run_ticks(replay_core, 0, 10, Vec3::Zero());
  run_ticks(remote_core, 0, 10, Vec3::Zero());
  AllocationCounter counter;
  run_ticks(replay_core, 10, 1990, Vec3::Zero());
  for (std::uint64_t t = 10; t < 2000; ++t) {
    device::DeviceReading reading;
    reading.position_m = Vec3(0.5, 0.0, 0.0);  // outside the workspace: clamped
    if (t % 7 == 0) reading.position_m.x() = std::numeric_limits<double>::infinity();
    remote.push(reading);
    const device::ForceCommandSample c = hostile(t, Vec3::Zero());
    remote_core.tick(tick_time(t), &c);
  }
  EXPECT_EQ(counter.count(), 0);
  EXPECT_GT(remote.rejected_non_finite(), 0U);
  EXPECT_GT(remote.clamped(), 0U);
}

}  // namespace
}  // namespace fahr::test
