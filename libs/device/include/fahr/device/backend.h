// What the servo loop needs from a device: a reading per tick and a force to
// hold until the next one. Simulated, replay, remote input and OpenHaptics
// back-ends implement it; the loop cannot tell them apart.
#pragma once

#include <chrono>
#include <string_view>

#include "fahr/device/types.h"

namespace fahr::device {

class Backend {
 public:
  virtual ~Backend() = default;
  virtual std::string_view name() const = 0;
  // The device state at servo time `now` (monotonic or simulated). Called
  // once per tick, before apply(). Must not allocate, block or log.
  virtual DeviceReading read(std::chrono::nanoseconds now) = 0;
  // Force on the stylus, device frame, N, held until the next tick. Already
  // limited by the safety layer. Must not allocate, block or log.
  virtual void apply(const Vec3& force_n) = 0;
};

}  // namespace fahr::device
