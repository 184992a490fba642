// Time-domain passivity observer and controller (Hannaford and Ryu 2002).
#include "fahr/device/passivity_controller.h"

#include <algorithm>
#include <cmath>

namespace fahr::device {

Vec3 PassivityController::apply(const Vec3& force_n, const Vec3& velocity_mps,
                                std::chrono::duration<double> dt) {
  if (!config_.enabled) return force_n;
  const double h = dt.count();
  // Energy left if this force were rendered as is.
  const double predicted_j = energy_j_ - force_n.dot(velocity_mps) * h;
  const double speed_squared = velocity_mps.squaredNorm();
  if (speed_squared < config_.min_speed_mps * config_.min_speed_mps) {
    // Too slow for the damper to do anything (its force is below a few mN).
    beta_ = 0.0;
    return force_n;
  }
  // beta |v|^2 h = -predicted brings the account back to zero.
  double beta = predicted_j >= 0.0
                    ? 0.0
                    : std::min(-predicted_j / (speed_squared * h), config_.max_damping_nspm);
  // The damper comes at once (passivity needs it now) but goes as a ramp,
  // its force |beta v| falling at most max_damping_release_n a tick: held a
  // little longer, a damper only dissipates more.
  beta = std::max(beta, beta_ - config_.max_damping_release_n / std::sqrt(speed_squared));
  beta_ = beta;
  if (beta <= 0.0) return force_n;
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
