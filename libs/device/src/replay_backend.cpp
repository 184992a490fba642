// Time-exact replay of a recorded DevicePose stream.
#include "fahr/device/replay_backend.h"

namespace fahr::device {

ReplayBackend::ReplayBackend(Recording recording) : recording_(std::move(recording)) {}

DeviceReading ReplayBackend::read(std::chrono::nanoseconds now) {
  DeviceReading reading;
  if (recording_.samples.empty()) {
    finished_ = true;
    reading.fault = true;  // nothing to replay: no force either
    return reading;
  }
  if (!started_) {
    started_ = true;
    start_ = now;
    index_ = 0;
  } else {
    const std::int64_t first_ns = recording_.samples.front().device_time_ns;
    const std::int64_t elapsed_ns = (now - start_).count();
    while (index_ + 1 < recording_.samples.size() &&
           recording_.samples[index_ + 1].device_time_ns - first_ns <= elapsed_ns) {
      ++index_;
    }
    finished_ = index_ + 1 >= recording_.samples.size();
  }
  const DevicePoseSample& s = recording_.samples[index_];
  reading.position_m = s.position_m;
  reading.orientation = s.orientation;
  reading.linear_velocity_mps = s.linear_velocity_mps;
  reading.angular_velocity_radps = s.angular_velocity_radps;
  reading.buttons = s.buttons;
  return reading;
}

}  // namespace fahr::device
