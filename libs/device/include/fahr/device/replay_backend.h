// Replays the DevicePose stream of a recording, time-exact: at servo time
// t (relative to the first read) it returns the newest recorded sample whose
// device time, relative to the first sample's, is <= t. A 1 kHz recording
// replayed by a 1 kHz loop is reproduced sample for sample. The recording is
// in the world frame, so the loop must run it with an identity workspace
// mapping. Forces are accepted and dropped (a recording cannot be pushed).
#pragma once

#include "fahr/device/backend.h"
#include "fahr/device/recording.h"

namespace fahr::device {

class ReplayBackend final : public Backend {
 public:
  explicit ReplayBackend(Recording recording);

  std::string_view name() const override { return "replay"; }
  DeviceReading read(std::chrono::nanoseconds now) override;
  void apply(const Vec3&) override {}

  bool finished() const { return finished_; }
  std::size_t index() const { return index_; }

 private:
  Recording recording_;
  bool started_ = false;
  bool finished_ = false;
  std::chrono::nanoseconds start_{0};
  std::size_t index_ = 0;
};

}  // namespace fahr::device
