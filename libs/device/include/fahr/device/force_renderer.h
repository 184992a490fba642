// The gateway's half of the fastest loop: from the newest ForceCommand (force
// F_k at the answered pose x_k, local stiffness K_k) it renders, at every
// servo tick, F = F_k - K_k (x_now - x_k), so a command that is a period or
// more old is corrected for where the stylus is now
// (docs/design/servo-rendering-and-passivity.md).
#pragma once

#include <cstdint>

#include "fahr/device/types.h"

namespace fahr::device {

struct RenderConfig {
  // The linearisation F_k - K_k dx holds near x_k only; past this distance,
  // m, (0, 0.1], the correction stops growing. 5 mm is about the depth over
  // which a tongue contact stays one contact.
  double max_correction_m = 5e-3;
  // Contacts push, they do not pull: the correction may shrink the force
  // along F_k's direction to zero but not reverse it (a stylus leaving the
  // tissue would otherwise be pulled back by the extrapolated spring).
  bool unilateral = true;
};

class ForceRenderer {
 public:
  // `max_stiffness_npm`: the device's stable stiffness, N/m, > 0.
  ForceRenderer(const RenderConfig& config, double max_stiffness_npm);

  // Takes a command already screened by SafetyGate (finite fields). K_k is
  // made symmetric (an asymmetric K is a curl field that does work around a
  // loop) and its eigenvalues clamped to [0, max stiffness] (negative
  // stiffness is active). No allocation.
  void set_command(const ForceCommandSample& command);
  void clear();
  // Keeps F_k and drops K_k: the stylus is no longer near x_k in a way the
  // linearisation knows (after a stall of the servo loop).
  void drop_stiffness() { stiffness_npm_.setZero(); }
  bool has_command() const { return has_command_; }
  std::uint64_t answered_pose_seq() const { return answered_pose_seq_; }
  const Vec3& torque_nm() const { return torque_nm_; }

  // Force on the stylus at `position_m` (world frame), N, not yet saturated.
  Vec3 render(const Vec3& position_m) const;

 private:
  RenderConfig config_;
  double max_stiffness_npm_;
  bool has_command_ = false;
  std::uint64_t answered_pose_seq_ = 0;
  Vec3 answered_position_m_ = Vec3::Zero();
  Vec3 force_n_ = Vec3::Zero();
  Mat3 stiffness_npm_ = Mat3::Zero();
  Vec3 torque_nm_ = Vec3::Zero();
};

}  // namespace fahr::device
