// A simulated device held by a virtual hand. The hand is an impedance (Hogan,
// "Impedance control", 1985): a spring and damper pull the stylus towards the
// scripted target, and the stylus plus hand mass integrates that pull plus
// the force the gateway renders. So a rendered contact force moves the
// stylus away from the script, as tissue stops a real hand, and the
// DevicePose stream depends on the force loop as it would with a person.
// Deterministic: the same commands give the same stream, bit for bit.
#pragma once

#include <chrono>

#include "fahr/device/backend.h"
#include "fahr/device/device_model.h"
#include "fahr/device/trajectory.h"
#include "fahr/device/workspace_mapping.h"

namespace fahr::device {

struct HandImpedance {
  // Stylus plus fingers, kg, > 0 (estimate: the Touch X arm's apparent mass
  // is tens of grams, a relaxed pen grip about 0.1 kg).
  double mass_kg = 0.15;
  // Grip stiffness towards the intended pose, N/m, > 0 (estimate within the
  // few hundred N/m reported for relaxed finger-wrist grips).
  double stiffness_npm = 400.0;
  // N s/m, >= 0; 12 is 0.8 of critical damping for the values above.
  double damping_nspm = 12.0;
};

class SimulatedBackend final : public Backend {
 public:
  // `period`: servo period; the hand is integrated over one period per apply().
  SimulatedBackend(Trajectory script, const HandImpedance& hand, const DeviceModel& model,
                   const WorkspaceMapping& mapping, std::chrono::nanoseconds period);

  std::string_view name() const override { return "simulated"; }
  DeviceReading read(std::chrono::nanoseconds now) override;
  void apply(const Vec3& force_n) override;

 private:
  Trajectory script_;
  HandImpedance hand_;
  WorkspaceMapping mapping_;
  Vec3 half_workspace_m_;
  double period_s_;
  double time_s_ = 0.0;
  Vec3 position_m_;  // device frame
  Vec3 velocity_mps_ = Vec3::Zero();
  Quat orientation_;
};

}  // namespace fahr::device
