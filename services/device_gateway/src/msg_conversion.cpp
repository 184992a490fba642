// Field-by-field copies between the library's structs and the msg types.
#include "fahr/gateway_service/msg_conversion.h"

namespace fahr::gateway_service {

namespace {
void put(const device::Vec3& v, msg::Vec3& out) {
  out.x(v.x());
  out.y(v.y());
  out.z(v.z());
}
device::Vec3 get(const msg::Vec3& v) {
  return device::Vec3(v.x(), v.y(), v.z());
}
}  // namespace

void to_msg(const device::DevicePoseSample& pose, std::uint32_t device_id, msg::DevicePose& out) {
  out.device_id(device_id);
  out.servo_tick(pose.servo_tick);
  out.device_time_ns(pose.device_time_ns);
  put(pose.position_m, out.world_from_stylus().position_m());
  auto& q = out.world_from_stylus().orientation();
  q.w(pose.orientation.w());
  q.x(pose.orientation.x());
  q.y(pose.orientation.y());
  q.z(pose.orientation.z());
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
  out.answered_position_m = get(in.answered_position_m());
  out.force_n = get(in.force_n());
  const auto& k = in.stiffness_npm().m();
  for (int i = 0; i < 9; ++i) out.stiffness_npm(i / 3, i % 3) = k[static_cast<std::size_t>(i)];
  out.torque_nm = get(in.torque_nm());
}

void reading_from_msg(const msg::DevicePose& in, device::DeviceReading& out) {
  out.position_m = get(in.world_from_stylus().position_m());
  const auto& q = in.world_from_stylus().orientation();
  out.orientation = device::Quat(q.w(), q.x(), q.y(), q.z());
  out.linear_velocity_mps = get(in.linear_velocity_mps());
  out.angular_velocity_radps = get(in.angular_velocity_radps());
  out.buttons = in.buttons();
}

}  // namespace fahr::gateway_service
