// The simulated intubation is deterministic (two runs, one DevicePose hash),
// the hand answers the rendered force (a wall changes where the stylus
// goes), and a recording replays sample for sample.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <vector>

#include "fahr/device/recording.h"
#include "fahr/device/replay_backend.h"
#include "fahr/device/simulated_backend.h"
#include "test_support.h"

namespace fahr::test {
namespace {

struct IntubationRun {
  std::uint64_t hash = 0;
  std::vector<device::DevicePoseSample> poses;
  double lowest_y_m = 1.0;
};

// The scripted intubation against a tongue-like wall (y = -0.5 mm, the
// pressing pose's height) through a jittery link: the full loop.
IntubationRun run_intubation(bool with_wall) {
  device::GatewayConfig config;
  device::SimulatedBackend backend(device::intubation_script(), device::HandImpedance{},
                                   config.model, config.mapping, config.period);
  device::ServoCore core(config, backend);
  VirtualWall wall;
  wall.wall_y_m = with_wall ? -0.5e-3 : -1.0;
  DelayLink link(DelayLink::Settings{});
  IntubationRun run;
  PoseHash hash;
  const auto ticks =
      static_cast<std::uint64_t>(device::intubation_script().duration().count() / 1e-3);
  for (std::uint64_t t = 0; t < ticks; ++t) {
    const auto& pose = core.tick(tick_time(t), link.receive(t));
    link.send(t, wall.answer(pose));
    hash.add(pose);
    run.poses.push_back(pose);
    run.lowest_y_m = std::min(run.lowest_y_m, pose.position_m.y());
  }
  run.hash = hash.value();
  return run;
}

TEST(Determinism, TwoSimulatedIntubationsGiveTheSameStream) {
  const IntubationRun first = run_intubation(true);
  const IntubationRun second = run_intubation(true);
  std::printf("intubation: %zu DevicePose samples, hash %016llx / %016llx\n", first.poses.size(),
              static_cast<unsigned long long>(first.hash),
              static_cast<unsigned long long>(second.hash));
  EXPECT_EQ(first.hash, second.hash);
  EXPECT_EQ(first.poses.size(), 13000U);
}

TEST(Determinism, RenderedForceMovesTheHand) {
  const IntubationRun free_hand = run_intubation(false);
  const IntubationRun against_wall = run_intubation(true);
  std::printf("lowest tip y: free %.2f mm, against the wall %.2f mm\n", free_hand.lowest_y_m * 1e3,
              against_wall.lowest_y_m * 1e3);
  // Free, the hand reaches the script's -6.5 mm; the wall holds it within
  // about F/k_wall of its surface (a few mm at 1400 N/m).
  EXPECT_LT(free_hand.lowest_y_m, -6.0e-3);
  EXPECT_GT(against_wall.lowest_y_m, -4.0e-3);
  EXPECT_NE(free_hand.hash, against_wall.hash);
}

TEST(Replay, ReproducesARecordingSampleForSample) {
  const IntubationRun recorded = run_intubation(true);
  const auto path = std::filesystem::temp_directory_path() / "fahr_device_replay_test.csv";
  {
    device::RecordingWriter writer(path);
    ASSERT_TRUE(writer.ok()) << writer.error();
    for (const auto& pose : recorded.poses) writer.write(pose);
  }
  device::Recording recording;
  const std::string error = device::read_recording(path, recording);
  ASSERT_TRUE(error.empty()) << error;
  ASSERT_EQ(recording.samples.size(), recorded.poses.size());

  device::GatewayConfig config;  // identity mapping: the recording is world frame
  device::ReplayBackend backend(std::move(recording));
  device::ServoCore core(config, backend);
  // Replay on a clock offset from the recording's: only relative time counts.
  const auto offset = std::chrono::seconds(1234);
  for (std::size_t i = 0; i < recorded.poses.size(); ++i) {
    const auto& pose = core.tick(offset + tick_time(i), nullptr);
    const auto& original = recorded.poses[i];
    ASSERT_EQ(pose.position_m, original.position_m) << "sample " << i;
    ASSERT_EQ(pose.linear_velocity_mps, original.linear_velocity_mps) << "sample " << i;
    ASSERT_EQ(pose.orientation.coeffs(), original.orientation.coeffs()) << "sample " << i;
    ASSERT_EQ(pose.buttons, original.buttons) << "sample " << i;
  }
  EXPECT_TRUE(backend.finished());
  std::filesystem::remove(path);
}

TEST(Replay, SkipsAndHoldsByTimeNotByCount) {
  device::Recording recording;
  for (int i = 0; i < 10; ++i) {
    device::DevicePoseSample s;
    s.device_time_ns = 5'000'000 + i * 2'000'000;  // recorded at 500 Hz
    s.position_m = Vec3(i, 0, 0);
    recording.samples.push_back(s);
  }
  device::ReplayBackend backend(std::move(recording));
  // Read at 1 kHz: every recorded sample is held for two ticks.
  for (int t = 0; t < 20; ++t) {
    EXPECT_EQ(backend.read(tick_time(static_cast<std::uint64_t>(t))).position_m.x(), t / 2) << t;
  }
}

TEST(Recording, BadLinesNameTheFileLineAndField) {
  const auto path = std::filesystem::temp_directory_path() / "fahr_device_bad_recording.csv";
  {
    device::RecordingWriter writer(path);
    writer.write(device::DevicePoseSample{});
  }
  {
    std::FILE* f = std::fopen(path.c_str(), "a");
    std::fputs("1,2,0.1,oops,0,1,0,0,0,0,0,0,0,0,0,0,7.9,0,0,0,2\n", f);
    std::fclose(f);
  }
  device::Recording recording;
  const std::string error = device::read_recording(path, recording);
  EXPECT_NE(error.find(":4: field py_m"), std::string::npos) << error;
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace fahr::test
