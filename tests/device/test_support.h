// Shared pieces of the gateway tests: a hand-held fixed backend, a stiff
// virtual wall standing in for the haptic service, and a DDS-like link that
// delays and drops ForceCommands with a fixed seed. Everything runs in
// simulated time: no sleeping, no threads.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <random>

#include "fahr/device/backend.h"
#include "fahr/device/servo_core.h"
#include "fahr/device/types.h"

namespace fahr::test {

using device::Vec3;

// A stylus moved by the test directly (position and velocity set per tick);
// records what the gateway applied.
class ScriptedBackend final : public device::Backend {
 public:
  std::string_view name() const override { return "scripted"; }
  device::DeviceReading read(std::chrono::nanoseconds) override { return reading; }
  void apply(const Vec3& force_n) override { applied_n = force_n; }

  device::DeviceReading reading;
  Vec3 applied_n = Vec3::Zero();
};

// The haptic service reduced to a wall: the half-space y < wall_y_m pushes
// back along +y with stiffness k (N/m). Answers a pose with F_k and, if
// `send_stiffness`, K_k = k e_y e_y^T (0 when not in contact).
struct VirtualWall {
  double wall_y_m = -0.5e-3;
  double stiffness_npm = 1400.0;
  bool send_stiffness = true;

  device::ForceCommandSample answer(const device::DevicePoseSample& pose) const {
    device::ForceCommandSample command;
    command.answered_pose_seq = pose.seq;
    command.answered_position_m = pose.position_m;
    const double depth_m = wall_y_m - pose.position_m.y();
    if (depth_m > 0.0) {
      command.force_n = Vec3(0.0, stiffness_npm * depth_m, 0.0);
      if (send_stiffness) command.stiffness_npm(1, 1) = stiffness_npm;
    }
    return command;
  }
};

// Best effort, keep last 1: every command is sent when its pose is
// published and arrives after a delay (base, or a 2-5 ms spike with some
// probability), or is lost in a burst. The gateway sees the newest arrived
// command, once.
class DelayLink {
 public:
  struct Settings {
    std::uint32_t seed = 7;
    int base_delay_ticks = 1;
    double spike_probability = 0.2;  // per command
    int spike_min_ticks = 2;
    int spike_max_ticks = 5;
    double burst_probability = 0.002;  // per tick: a lost burst starts
    int burst_min_ticks = 10;
    int burst_max_ticks = 40;
  };
  explicit DelayLink(const Settings& settings) : settings_(settings), rng_(settings.seed) {}

  void send(std::uint64_t tick, const device::ForceCommandSample& command) {
    if (burst_left_ == 0 && uniform_(rng_) < settings_.burst_probability) {
      burst_left_ = pick(settings_.burst_min_ticks, settings_.burst_max_ticks);
    }
    if (burst_left_ > 0) {
      --burst_left_;
      ++dropped_;
      return;
    }
    int delay = settings_.base_delay_ticks;
    if (uniform_(rng_) < settings_.spike_probability)
      delay = pick(settings_.spike_min_ticks, settings_.spike_max_ticks);
    in_flight_.push_back({tick + static_cast<std::uint64_t>(delay), command});
  }

  // The newest command that has arrived by `tick` and is newer than the last
  // one delivered, or null.
  const device::ForceCommandSample* receive(std::uint64_t tick) {
    const device::ForceCommandSample* newest = nullptr;
    for (auto it = in_flight_.begin(); it != in_flight_.end();) {
      if (it->arrival_tick <= tick) {
        if (it->command.answered_pose_seq > delivered_seq_) {
          delivered_seq_ = it->command.answered_pose_seq;
          holder_ = it->command;
          newest = &holder_;
        }
        it = in_flight_.erase(it);
      } else {
        ++it;
      }
    }
    return newest;
  }
  std::uint64_t dropped() const { return dropped_; }

 private:
  struct InFlight {
    std::uint64_t arrival_tick;
    device::ForceCommandSample command;
  };
  int pick(int low, int high) { return std::uniform_int_distribution<int>(low, high)(rng_); }

  Settings settings_;
  std::mt19937 rng_;
  std::uniform_real_distribution<double> uniform_{0.0, 1.0};
  std::deque<InFlight> in_flight_;
  device::ForceCommandSample holder_;
  std::uint64_t delivered_seq_ = 0;
  int burst_left_ = 0;
  std::uint64_t dropped_ = 0;
};

inline std::chrono::nanoseconds tick_time(std::uint64_t tick) {
  return std::chrono::milliseconds(1) * static_cast<std::int64_t>(tick);
}

// 64-bit FNV-1a over the bytes of a pose's fields (values, not padding).
class PoseHash {
 public:
  void add(const device::DevicePoseSample& pose) {
    add_value(pose.seq);
    add_value(pose.device_time_ns);
    for (int i = 0; i < 3; ++i) {
      add_value(pose.position_m[i]);
      add_value(pose.linear_velocity_mps[i]);
      add_value(pose.rendered_force_n[i]);
    }
    add_value(pose.orientation.w());
    add_value(pose.orientation.x());
    add_value(pose.orientation.y());
    add_value(pose.orientation.z());
    add_value(pose.renderable_force_n);
    add_value(static_cast<std::uint32_t>(pose.safety_state));
  }
  std::uint64_t value() const { return value_; }

 private:
  template <class T>
  void add_value(const T& value) {
    const auto* bytes = reinterpret_cast<const unsigned char*>(&value);
    for (std::size_t i = 0; i < sizeof(T); ++i) {
      value_ ^= bytes[i];
      value_ *= 1099511628211ULL;
    }
  }
  std::uint64_t value_ = 14695981039346656037ULL;
};

}  // namespace fahr::test
