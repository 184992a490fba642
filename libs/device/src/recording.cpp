// The text recording of a DevicePose stream (format in the header).
#include "fahr/device/recording.h"

#include <cerrno>
#include <cinttypes>
#include <cstdlib>
#include <cstring>
#include <fstream>

namespace fahr::device {

namespace {

constexpr const char* kMagic = "# fahr device recording v1";
constexpr const char* kColumns =
    "servo_tick,device_time_ns,px_m,py_m,pz_m,qw,qx,qy,qz,vx_mps,vy_mps,vz_mps,wx_radps,wy_radps,"
    "wz_radps,"
    "buttons,renderable_force_n,fx_n,fy_n,fz_n,safety_state";
constexpr const char* kFieldNames[] = {"servo_tick",
                                       "device_time_ns",
                                       "px_m",
                                       "py_m",
                                       "pz_m",
                                       "qw",
                                       "qx",
                                       "qy",
                                       "qz",
                                       "vx_mps",
                                       "vy_mps",
                                       "vz_mps",
                                       "wx_radps",
                                       "wy_radps",
                                       "wz_radps",
                                       "buttons",
                                       "renderable_force_n",
                                       "fx_n",
                                       "fy_n",
                                       "fz_n",
                                       "safety_state"};
constexpr int kFieldCount = 21;

}  // namespace

RecordingWriter::RecordingWriter(const std::filesystem::path& path) {
  file_ = std::fopen(path.c_str(), "w");
  if (file_ == nullptr) {
    error_ = path.string() + ": cannot open for writing: " + std::strerror(errno);
    return;
  }
  std::fprintf(file_, "%s\n%s\n", kMagic, kColumns);
}

RecordingWriter::~RecordingWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void RecordingWriter::write(const DevicePoseSample& s) {
  if (file_ == nullptr) return;
  // %.17g round-trips every double exactly.
  std::fprintf(
      file_,
      "%" PRIu64 ",%" PRId64
      ",%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%" PRIu32
      ",%.17g,%.17g,%.17g,%.17g,%u\n",
      s.servo_tick, s.device_time_ns, s.position_m.x(), s.position_m.y(), s.position_m.z(),
      s.orientation.w(), s.orientation.x(), s.orientation.y(), s.orientation.z(),
      s.linear_velocity_mps.x(), s.linear_velocity_mps.y(), s.linear_velocity_mps.z(),
      s.angular_velocity_radps.x(), s.angular_velocity_radps.y(), s.angular_velocity_radps.z(),
      s.buttons, s.renderable_force_n, s.rendered_force_n.x(), s.rendered_force_n.y(),
      s.rendered_force_n.z(), static_cast<unsigned>(s.safety_state));
}

std::string read_recording(const std::filesystem::path& path, Recording& out) {
  out.samples.clear();
  std::ifstream in(path);
  if (!in) return path.string() + ": cannot open for reading";
  std::string line;
  if (!std::getline(in, line) || line != kMagic)
    return path.string() + ":1: not a fahr device recording v1";
  if (!std::getline(in, line) || line != kColumns)
    return path.string() + ":2: unexpected column header";
  int line_number = 2;
  while (std::getline(in, line)) {
    ++line_number;
    if (line.empty()) continue;
    double values[kFieldCount];
    const char* cursor = line.c_str();
    for (int field = 0; field < kFieldCount; ++field) {
      char* end = nullptr;
      values[field] = std::strtod(cursor, &end);
      const char expected = field + 1 < kFieldCount ? ',' : '\0';
      if (end == cursor || *end != expected) {
        return path.string() + ":" + std::to_string(line_number) + ": field " + kFieldNames[field] +
               " is not a number";
      }
      cursor = end + (expected == ',' ? 1 : 0);
    }
    // Integers are read back exactly through strtoull/strtoll on their own text.
    DevicePoseSample s;
    const char* text = line.c_str();
    char* end = nullptr;
    s.servo_tick = std::strtoull(text, &end, 10);
    s.device_time_ns = std::strtoll(end + 1, &end, 10);
    s.position_m = Vec3(values[2], values[3], values[4]);
    s.orientation = Quat(values[5], values[6], values[7], values[8]);
    s.linear_velocity_mps = Vec3(values[9], values[10], values[11]);
    s.angular_velocity_radps = Vec3(values[12], values[13], values[14]);
    s.buttons = static_cast<std::uint32_t>(values[15]);
    s.renderable_force_n = values[16];
    s.rendered_force_n = Vec3(values[17], values[18], values[19]);
    const int state = static_cast<int>(values[20]);
    if (state < 0 || state > static_cast<int>(SafetyState::kFault)) {
      return path.string() + ":" + std::to_string(line_number) +
             ": field safety_state out of range [0, 4]";
    }
    s.safety_state = static_cast<SafetyState>(state);
    out.samples.push_back(s);
  }
  return {};
}

}  // namespace fahr::device
