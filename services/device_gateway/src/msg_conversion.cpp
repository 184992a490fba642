// Field-by-field copies between the library's structs and the msg types.
#include "fahr/gateway_service/msg_conversion.h"

#include "fahr/common/wire_eigen.h"

namespace fahr::gateway_service {

using common::put;
using common::to_eigen;

void to_msg(const device::DevicePoseSample& pose, std::uint32_t device_id, msg::DevicePose& out) {
  out.device_id(device_id);
  out.servo_tick(pose.servo_tick);
  out.device_time_ns(pose.device_time_ns);
  put(pose.position_m, out.world_from_stylus().position_m());
  put(pose.orientation, out.world_from_stylus().orientation());
  put(pose.linear_velocity_mps, out.linear_velocity_mps());
  put(pose.angular_velocity_radps, out.angular_velocity_radps());
  out.buttons(pose.buttons);
  out.renderable_force_n(pose.renderable_force_n);
  out.max_stiffness_npm(pose.max_stiffness_npm);
  put(pose.rendered_force_n, out.rendered_force_n());
  // Same enumerator order in safety_state and the IDL (types.h).
  out.safety_state(
      static_cast<msg::DeviceSafetyState>(static_cast<std::uint32_t>(pose.safety_state)));
}

void from_msg(const msg::ForceCommand& in, device::ForceCommandSample& out) {
  out.answered_pose_seq = in.answered_pose_seq();
  out.answered_position_m = to_eigen(in.answered_position_m());
  out.force_n = to_eigen(in.force_n());
  out.stiffness_npm = to_eigen(in.stiffness_npm());
  out.torque_nm = to_eigen(in.torque_nm());
  out.transition = in.reason() != msg::FORCE_RENDERED;
}

void reading_from_msg(const msg::DevicePose& in, device::DeviceReading& out) {
  out.position_m = to_eigen(in.world_from_stylus().position_m());
  out.orientation = to_eigen(in.world_from_stylus().orientation());  // as sent, not normalised
  out.linear_velocity_mps = to_eigen(in.linear_velocity_mps());
  out.angular_velocity_radps = to_eigen(in.angular_velocity_radps());
  out.buttons = in.buttons();
}

}  // namespace fahr::gateway_service
