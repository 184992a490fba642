// The Touch X through the OpenHaptics HD API. Compiled only when CMake finds
// HD/hd.h and libHD (FAHR_HAVE_OPENHAPTICS). Thin: the HD scheduler owns
// the 1 kHz servo thread, so the service runs its tick inside the scheduler
// callback: hdBeginFrame, read(), the tick, apply(), hdEndFrame.
#pragma once

#include <functional>
#include <string>

#include "fahr/device/backend.h"

namespace fahr::device {

class OpenHapticsBackend final : public Backend {
 public:
  // The tick the scheduler runs every servo period; returns false to stop.
  using Tick = std::function<bool()>;

  OpenHapticsBackend() = default;
  ~OpenHapticsBackend() override;

  // Opens the default device, checks (and if needed updates) calibration,
  // enables force output. Empty on success, else the HD error text.
  std::string open();
  // Runs `tick` at every scheduler tick until it returns false (blocks).
  std::string run(Tick tick);

  std::string_view name() const override { return "openhaptics"; }
  DeviceReading read(std::chrono::nanoseconds now) override;
  void apply(const Vec3& force_n) override;

 private:
  unsigned int handle_ = 0;
  bool open_ = false;
  Tick tick_;
};

}  // namespace fahr::device
