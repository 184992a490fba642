// The Touch X through OpenHaptics' HD API. Built only with the SDK present;
// untested here (no device, no SDK on the build machines).
#include "fahr/device/openhaptics_backend.h"

#include <HD/hd.h>

namespace fahr::device {

namespace {

std::string hd_error_text(const char* what) {
  const HDErrorInfo error = hdGetError();
  if (!HD_DEVICE_ERROR(error)) return {};
  return std::string(what) + ": " + hdGetErrorString(error.errorCode);
}

HDCallbackCode HDCALLBACK servo_callback(void* data) {
  auto* tick = static_cast<OpenHapticsBackend::Tick*>(data);
  hdBeginFrame(hdGetCurrentDevice());
  const bool more = (*tick)();
  hdEndFrame(hdGetCurrentDevice());
  return more ? HD_CALLBACK_CONTINUE : HD_CALLBACK_DONE;
}

}  // namespace

OpenHapticsBackend::~OpenHapticsBackend() {
  if (open_) {
    hdStopScheduler();
    hdDisable(HD_FORCE_OUTPUT);
    hdDisableDevice(handle_);
  }
}

std::string OpenHapticsBackend::open() {
  handle_ = hdInitDevice(HD_DEFAULT_DEVICE);
  if (auto error = hd_error_text("hdInitDevice"); !error.empty()) return error;
  open_ = true;
  // Encoder calibration: the inkwell or an automatic update if the device
  // offers one; a device that needs the operator is reported, not forced.
  const HDenum calibration = hdCheckCalibration();
  if (calibration == HD_CALIBRATION_NEEDS_UPDATE) {
    HDint styles = 0;
    hdGetIntegerv(HD_CALIBRATION_STYLE, &styles);
    if (styles & HD_CALIBRATION_AUTO)
      hdUpdateCalibration(HD_CALIBRATION_AUTO);
    else if (styles & HD_CALIBRATION_INKWELL)
      hdUpdateCalibration(HD_CALIBRATION_INKWELL);
  } else if (calibration == HD_CALIBRATION_NEEDS_MANUAL_INPUT) {
    return "calibration needs manual input: put the stylus in the inkwell and restart";
  }
  hdEnable(HD_FORCE_OUTPUT);
  return hd_error_text("hdEnable(HD_FORCE_OUTPUT)");
}

std::string OpenHapticsBackend::run(Tick tick) {
  tick_ = std::move(tick);
  const HDSchedulerHandle handle =
      hdScheduleAsynchronous(servo_callback, &tick_, HD_MAX_SCHEDULER_PRIORITY);
  hdStartScheduler();
  if (auto error = hd_error_text("hdStartScheduler"); !error.empty()) return error;
  hdWaitForCompletion(handle, HD_WAIT_INFINITE);
  hdStopScheduler();
  hdUnschedule(handle);
  return {};
}

DeviceReading OpenHapticsBackend::read(std::chrono::nanoseconds) {
  DeviceReading reading;
  HDdouble position_mm[3] = {0, 0, 0};
  HDdouble velocity_mmps[3] = {0, 0, 0};
  HDdouble transform[16] = {};
  HDint buttons = 0;
  hdGetDoublev(HD_CURRENT_POSITION, position_mm);
  hdGetDoublev(HD_CURRENT_VELOCITY, velocity_mmps);
  hdGetDoublev(HD_CURRENT_TRANSFORM, transform);
  hdGetIntegerv(HD_CURRENT_BUTTONS, &buttons);
  // HD reports millimetres; the transform is column-major 4x4.
  reading.position_m = Vec3(position_mm[0], position_mm[1], position_mm[2]) * 1e-3;
  reading.linear_velocity_mps = Vec3(velocity_mmps[0], velocity_mmps[1], velocity_mmps[2]) * 1e-3;
  Mat3 rotation;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) rotation(row, col) = transform[col * 4 + row];
  }
  reading.orientation = Quat(rotation).normalized();
  reading.buttons = static_cast<std::uint32_t>(buttons);
  reading.fault = HD_DEVICE_ERROR(hdGetError());
  return reading;
}

void OpenHapticsBackend::apply(const Vec3& force_n) {
  const HDdouble force[3] = {force_n.x(), force_n.y(), force_n.z()};
  hdSetDoublev(HD_CURRENT_FORCE, force);
}

}  // namespace fahr::device
