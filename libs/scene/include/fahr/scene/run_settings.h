// How a scene runs: clock mode, service rates, DDS participation.
#pragma once

#include <chrono>
#include <string_view>

#include "fahr/scene/defaults.h"

namespace fahr::scene {

enum class RunMode {
  kRealtime,  // the device gateway's servo loop clocks the haptic domain
  kLockstep,  // a SimClock grants steps; bit-for-bit reproducible
};

enum class DdsVendor { kCycloneDds, kFastDds };

std::string_view to_string(RunMode mode);
std::string_view to_string(DdsVendor vendor);

// Rates are frequencies; use the period helpers for durations.
struct Rates {
  double haptic_hz = kDefaultHapticHz;  // device servo and haptic tick, (0, 10000]
  double fem_hz = kDefaultFemHz;        // FEM step rate, (0, 10000]
  double status_hz = kDefaultStatusHz;  // ServiceStatus rate, (0, 1000]

  std::chrono::nanoseconds haptic_period() const;
  std::chrono::nanoseconds fem_period() const;
  std::chrono::nanoseconds status_period() const;
};

struct RunSettings {
  RunMode mode = RunMode::kRealtime;
  // Lockstep: one SimClock step. Defaults to the period of the fastest of
  // haptic_hz and fem_hz; the haptic and FEM periods are whole multiples of it.
  std::chrono::nanoseconds base_period{0};
  // Zero: run until stopped.
  std::chrono::nanoseconds duration{0};
  // Lockstep: haptic tick k reads the FEM state this many FEM steps behind
  // the newest it could see, [0, 100].
  int fem_state_delay_steps = kDefaultFemStateDelaySteps;
  // Real time: busy-wait for the next period (opt-in: starves small machines).
  bool spin_wait = kDefaultSpinWait;
};

struct DdsSettings {
  DdsVendor vendor = DdsVendor::kCycloneDds;
  int domain_id = kDefaultDomainId;  // [0, 230]
};

}  // namespace fahr::scene
