// Two lockstep participants for the determinism proof: "fast" (every base
// step, 1 kHz) and "slow" (every 10th, 100 Hz) exchange DevicePose and
// ForceCommand through chaotic maps, so any difference in which step of the
// other one each reads would change their output hashes.
#pragma once

#include <cstdint>
#include <string>

#include "fahr/common/participant.h"

namespace fahr::test {

inline constexpr std::uint64_t kFastPeriod = 1;
inline constexpr std::uint64_t kSlowPeriod = 10;

// Runs one participant until the coordinator stops the run. `jitter_seed`
// != 0 adds random sleeps (up to 300 us) to shake the timing. Returns the
// participant's output hash.
std::uint64_t run_lockstep_participant(common::Participant& participant, const std::string& role,
                                       std::uint32_t jitter_seed);

}  // namespace fahr::test
