// Time-domain passivity observer and controller (Hannaford and Ryu,
// "Time-domain passivity control of haptic interfaces", IEEE Trans. Robotics
// and Automation 18(1), 2002; the impedance-causality form of Ryu, Kwon and
// Hannaford, 2004).
//
// The one-port seen by the hand is everything behind the stylus: the
// renderer, the DDS link and the haptic service. The observer integrates the
// energy that port has absorbed from the hand,
//     W(n) = W(n-1) - F(n) . v(n) dt      (F: force on the stylus, v: its velocity),
// which stays >= 0 for a passive port. A late or lost ForceCommand (a wall
// whose force is computed at an old pose) makes W negative: the port has
// pushed more energy into the hand than it received. The controller then
// adds a damping force -beta v with beta chosen to bring W back to zero this
// tick (bounded by max_damping_nspm so the damper itself stays stable on a
// sampled device; its force falls by at most max_damping_release_n a tick
// when no longer needed); what the bound leaves is carried to the next tick.
//
// The energy is observed in the world frame. With a workspace motion scale
// s != 1 it is s times the device-frame energy; its sign, all that passivity
// needs, is the same.
#pragma once

#include <chrono>

#include "fahr/device/types.h"

namespace fahr::device {

struct PassivityConfig {
  bool enabled = true;
  // Upper bound of the controller's damping, N s/m, >= 0. A discrete damper
  // b is stable on a device of mass m at period T roughly while b < m / T
  // (Colgate and Schenkel); 0.1 kg at 1 ms gives 100, halved for margin.
  double max_damping_nspm = 50.0;
  // Below this speed, m/s, the damper can do nothing useful (and beta would
  // blow up): the deficit waits for motion. 1e-4 m/s is a few encoder counts
  // of the Touch X per second.
  double min_speed_mps = 1e-4;
  // Cap of the stored energy, J, > 0: a long dissipative contact would
  // otherwise bank energy that a later fault could release all at once. The
  // largest energy a legitimate spring can hold at the device's limits is
  // F_peak^2 / (2 K_max) = 7.9^2 / (2 * 1480) = 21 mJ for the Touch X;
  // 50 mJ leaves margin for hand damping.
  double max_stored_energy_j = 0.05;
  // Largest fall of the damper's force |beta v| per tick, N, > 0: the
  // damper goes as a ramp, not as a step the hand feels (the 0.1 N a tick
  // of the station's other fault paths). It still comes at once.
  double max_damping_release_n = 0.1;
};

class PassivityController {
 public:
  explicit PassivityController(const PassivityConfig& config) : config_(config) {}

  // The force to render with the controller's damping added if the observed
  // energy would go negative this tick.
  Vec3 apply(const Vec3& force_n, const Vec3& velocity_mps, std::chrono::duration<double> dt);
  // Updates the observer with the force actually rendered (after safety
  // limits), so the account is of what the hand really received.
  void account(const Vec3& rendered_force_n, const Vec3& velocity_mps,
               std::chrono::duration<double> dt);

  // Energy the controller's damper has removed since start, J, >= 0.
  double dissipated_energy_j() const { return dissipated_j_; }
  // Ticks in which the controller added damping.
  std::uint64_t active_ticks() const { return active_ticks_; }

 private:
  PassivityConfig config_;
  double energy_j_ = 0.0;
  double beta_ = 0.0;  // the damping of the last tick, N s/m
  double dissipated_j_ = 0.0;
  std::uint64_t active_ticks_ = 0;
};

}  // namespace fahr::device
