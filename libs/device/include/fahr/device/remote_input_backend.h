// Poses from elsewhere (the browser's mouse device publishes DevicePose on
// "fahr/RemoteInput"): the main pushes each new sample, the loop reads the
// newest valid one. The same safety rules apply to the forces; the input
// itself is screened too: non-finite poses are rejected and counted, and
// positions are clamped to the device workspace so a remote client cannot
// teleport the tool across the scene.
#pragma once

#include <cstdint>

#include "fahr/device/backend.h"
#include "fahr/device/device_model.h"

namespace fahr::device {

class RemoteInputBackend final : public Backend {
 public:
  explicit RemoteInputBackend(const DeviceModel& model);

  std::string_view name() const override { return "remote"; }
  // Called by the servo thread (the main polls the topic in the tick).
  // Returns false (and counts) if the sample has a non-finite field.
  bool push(const DeviceReading& reading);
  DeviceReading read(std::chrono::nanoseconds now) override;
  void apply(const Vec3& /*force_n*/) override {}  // a remote input renders no force

  std::uint64_t rejected_non_finite() const { return rejected_non_finite_; }
  std::uint64_t clamped() const { return clamped_; }

 private:
  Vec3 half_workspace_m_;
  DeviceReading newest_;
  std::uint64_t rejected_non_finite_ = 0;
  std::uint64_t clamped_ = 0;
};

}  // namespace fahr::device
