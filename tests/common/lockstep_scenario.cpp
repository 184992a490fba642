// The fast/slow lockstep scenario.
#include "lockstep_scenario.h"

#include <chrono>
#include <cmath>
#include <random>
#include <stdexcept>
#include <thread>

#include "fahr/common/lockstep.h"

namespace fahr::test {
namespace {

using namespace std::chrono_literals;
using common::lockstep_output_qos;
using common::producer_step_for;

constexpr auto kGrantTimeout = 20s;

class Jitter {
 public:
  explicit Jitter(std::uint32_t seed) : enabled_(seed != 0), rng_(seed) {}
  void maybe_sleep() {
    if (enabled_) std::this_thread::sleep_for(std::chrono::microseconds(rng_() % 300));
  }

 private:
  bool enabled_;
  std::mt19937 rng_;
};

std::uint64_t run_fast(common::Participant& participant, std::uint32_t jitter_seed) {
  common::Publisher<msg::DevicePose> out(participant, lockstep_output_qos<msg::DevicePose>());
  common::StepInput<msg::ForceCommand> in(participant);
  common::LockstepClient client(participant, "fast");
  client.join();
  Jitter jitter(jitter_seed);
  common::OutputHash hash;
  double x = 0.123456789;
  msg::DevicePose pose;
  for (std::uint64_t k = 0; client.wait_for_grant(k, kGrantTimeout); ++k) {
    double force = 0.0;
    if (auto s = producer_step_for(k, kSlowPeriod)) {
      const msg::ForceCommand* command = in.wait(*s, kGrantTimeout);
      if (command == nullptr) throw std::runtime_error("fast: input of slow step missing");
      force = command->force_n().x();
    }
    // Logistic map at r = 3.99: chaotic, so a wrong input shows at once.
    x = 3.99 * x * (1.0 - x);
    x = std::fabs(std::fmod(x + 1e-3 * force, 1.0));
    jitter.maybe_sleep();
    pose.world_from_stylus().position_m().x(x);
    pose.servo_tick(k);
    pose.header().sim_step(k);
    pose.header().sim_time_ns(static_cast<std::int64_t>(k) * 1'000'000);
    out.write(pose);
    hash.add(pose);
    client.complete_through(k, hash.value());
  }
  return hash.value();
}

std::uint64_t run_slow(common::Participant& participant, std::uint32_t jitter_seed) {
  common::Publisher<msg::ForceCommand> out(participant, lockstep_output_qos<msg::ForceCommand>());
  common::StepInput<msg::DevicePose> in(participant);
  common::LockstepClient client(participant, "slow");
  client.join();
  Jitter jitter(jitter_seed);
  common::OutputHash hash;
  double y = 0.5;
  msg::ForceCommand command;
  for (std::uint64_t k = 0; client.wait_for_grant(k, kGrantTimeout); k += kSlowPeriod) {
    if (auto s = producer_step_for(k, kFastPeriod)) {
      const msg::DevicePose* pose = in.wait(*s, kGrantTimeout);
      if (pose == nullptr) throw std::runtime_error("slow: input of fast step missing");
      y = std::sin(7.0 * y + 3.0 * pose->world_from_stylus().position_m().x());
    }
    jitter.maybe_sleep();
    command.force_n().x(y);
    command.header().sim_step(k);
    command.header().sim_time_ns(static_cast<std::int64_t>(k) * 1'000'000);
    out.write(command);
    hash.add(command);
    // Nothing to do until the next multiple of the period.
    client.complete_through(k + kSlowPeriod - 1, hash.value());
  }
  return hash.value();
}

}  // namespace

std::uint64_t run_lockstep_participant(common::Participant& participant, const std::string& role,
                                       std::uint32_t jitter_seed) {
  if (role == "fast") return run_fast(participant, jitter_seed);
  if (role == "slow") return run_slow(participant, jitter_seed);
  throw std::invalid_argument("unknown lockstep role " + role);
}

}  // namespace fahr::test
