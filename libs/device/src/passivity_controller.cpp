// Time-domain passivity observer and controller (Hannaford and Ryu 2002).
#include "fahr/device/passivity_controller.h"

#include <algorithm>

namespace fahr::device {

Vec3 PassivityController::apply(const Vec3& force_n, const Vec3& velocity_mps,
                                std::chrono::duration<double> dt) {
  if (!config_.enabled) return force_n;
  const double h = dt.count();
  // Energy left if this force were rendered as is.
  const double predicted_j = energy_j_ - force_n.dot(velocity_mps) * h;
  const double speed_squared = velocity_mps.squaredNorm();
  if (predicted_j >= 0.0 || speed_squared < config_.min_speed_mps * config_.min_speed_mps)
    return force_n;
  // beta |v|^2 h = -predicted brings the account back to zero.
  const double beta = std::min(-predicted_j / (speed_squared * h), config_.max_damping_nspm);
  ++active_ticks_;
  dissipated_j_ += beta * speed_squared * h;
  return force_n - beta * velocity_mps;
}

void PassivityController::account(const Vec3& rendered_force_n, const Vec3& velocity_mps,
                                  std::chrono::duration<double> dt) {
  energy_j_ -= rendered_force_n.dot(velocity_mps) * dt.count();
  energy_j_ = std::min(energy_j_, config_.max_stored_energy_j);
}

}  // namespace fahr::device
