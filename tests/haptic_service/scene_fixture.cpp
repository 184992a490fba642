// Shared neonatal set-up and pose helpers (see scene_fixture.h).
#include "scene_fixture.h"

#include <cmath>
#include <numbers>

#include "fahr/common/wire_eigen.h"

namespace fahr::haptic_service::test {

const NeonatalScene& neonatal_scene() {
  static const NeonatalScene loaded = [] {
    NeonatalScene s;
    // The scene as shipped, with the tool's stop at the anatomy on (the
    // shipped scene has it off while the FEM cannot take a wedged blade).
    auto scene = std::make_shared<scene::Scene>(
        *scene::load_scene(FAHR_SOURCE_DIR "/deployment/scenes/neonatal_intubation.yaml"));
    scene->contact.tool_stops_at_anatomy = true;
    s.scene = scene;
    s.setup = set_up(*s.scene);
    return s;
  }();
  return loaded;
}

msg::DevicePose device_pose(std::uint64_t tick, const Eigen::Vector3d& position_m, double pitch_deg,
                            double renderable_force_n) {
  msg::DevicePose pose;
  pose.header().seq(tick + 1);
  pose.header().sim_step(tick);
  pose.header().sim_time_ns(static_cast<std::int64_t>(tick) * 1000000);
  pose.device_id(1);
  pose.servo_tick(tick);
  common::put(position_m, pose.world_from_stylus().position_m());
  const double half = 0.5 * pitch_deg * std::numbers::pi / 180.0;
  common::put(Eigen::Quaterniond(std::cos(half), 0.0, 0.0, std::sin(half)),
              pose.world_from_stylus().orientation());
  pose.renderable_force_n(renderable_force_n);
  pose.max_stiffness_npm(1480.0);
  // A device rendering the commands (one that is not gets zero force).
  pose.safety_state(msg::DEVICE_FORCE_ENABLED);
  return pose;
}

collision::RigidBody rigid_body(const RigidField& field) {
  collision::RigidBody body;
  body.id = field.scene_body->id;
  body.sdf = field.sdf.get();
  body.world_from_body =
      Eigen::Translation3d(field.scene_body->pose.position_m) * field.scene_body->pose.orientation;
  return body;
}

}  // namespace fahr::haptic_service::test
