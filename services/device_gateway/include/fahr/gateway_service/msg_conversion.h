// The library's plain structs to and from the generated topic types. Copies
// into existing samples: nothing allocates (the types hold no strings or
// sequences).
#pragma once

#include "device_pose.h"
#include "fahr/device/types.h"
#include "force_command.h"

namespace fahr::gateway_service {

void to_msg(const device::DevicePoseSample& pose, std::uint32_t device_id, msg::DevicePose& out);
void from_msg(const msg::ForceCommand& in, device::ForceCommandSample& out);
// A remote input pose (DevicePose on fahr/RemoteInput) as a device reading.
void reading_from_msg(const msg::DevicePose& in, device::DeviceReading& out);

}  // namespace fahr::gateway_service
