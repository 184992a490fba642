// A recording of the DevicePose stream, until the MCAP logger exists: a text
// file, one sample per line, every double printed with 17 significant digits
// so it reads back bit for bit.
//
//   # fahr device recording v1
//   servo_tick,device_time_ns,px_m,py_m,pz_m,qw,qx,qy,qz,vx_mps,vy_mps,vz_mps,
//     wx_radps,wy_radps,wz_radps,buttons,renderable_force_n,fx_n,fy_n,fz_n,safety_state
//   0,1000000,0.012,...
//
// Positions, velocities and forces are world frame (as published).
#pragma once

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "fahr/device/types.h"

namespace fahr::device {

class RecordingWriter {
 public:
  // Opens (truncates) the file and writes the header. Check ok() / error().
  explicit RecordingWriter(const std::filesystem::path& path);
  ~RecordingWriter();
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  bool ok() const { return file_ != nullptr; }
  const std::string& error() const { return error_; }
  // Buffered by stdio: call outside the servo tick (it may block on I/O).
  void write(const DevicePoseSample& sample);

 private:
  std::FILE* file_ = nullptr;
  std::string error_;
};

struct Recording {
  std::vector<DevicePoseSample> samples;
};

// Reads a whole recording. Empty string on success; otherwise an error
// naming the file, the line and the field.
std::string read_recording(const std::filesystem::path& path, Recording& out);

}  // namespace fahr::device
