// F = F_k - K_k (x_now - x_k), with K_k conditioned and the correction
// bounded (see the header for why).
#include "fahr/device/force_renderer.h"

#include <Eigen/Eigenvalues>
#include <algorithm>

#include "fahr/device/safety_gate.h"

namespace fahr::device {

ForceRenderer::ForceRenderer(const RenderConfig& config, double max_stiffness_npm)
    : config_(config), max_stiffness_npm_(max_stiffness_npm) {}

void ForceRenderer::set_command(const ForceCommandSample& command) {
  answered_pose_seq_ = command.answered_pose_seq;
  answered_position_m_ = command.answered_position_m;
  // Huge but finite forces would overflow the products below; no device
  // comes near 1e6 N, and the safety layer saturates far lower anyway.
  constexpr double kArithmeticBoundN = 1e6;
  force_n_ = saturate(command.force_n, kArithmeticBoundN);
  torque_nm_ = command.torque_nm;
  const Mat3 symmetric = 0.5 * (command.stiffness_npm + command.stiffness_npm.transpose());
  // Closed-form 3x3 eigen-decomposition: fixed size, no allocation.
  Eigen::SelfAdjointEigenSolver<Mat3> solver;
  solver.computeDirect(symmetric);
  const Vec3 clamped = solver.eigenvalues().cwiseMax(0.0).cwiseMin(max_stiffness_npm_);
  stiffness_npm_ = solver.eigenvectors() * clamped.asDiagonal() * solver.eigenvectors().transpose();
  has_command_ = true;
}

void ForceRenderer::clear() {
  has_command_ = false;
  answered_pose_seq_ = 0;
  force_n_.setZero();
  stiffness_npm_.setZero();
  torque_nm_.setZero();
}

Vec3 ForceRenderer::render(const Vec3& position_m) const {
  if (!has_command_) return Vec3::Zero();
  Vec3 displacement = position_m - answered_position_m_;
  const double distance = displacement.norm();
  if (distance > config_.max_correction_m) displacement *= config_.max_correction_m / distance;
  Vec3 force = force_n_ - stiffness_npm_ * displacement;
  const double command_norm = force_n_.norm();
  // 1e-9 N: below any force the device resolves; a zero F_k has no direction.
  constexpr double kNoDirectionN = 1e-9;
  if (config_.unilateral && command_norm > kNoDirectionN) {
    const Vec3 direction = force_n_ / command_norm;
    const double along = force.dot(direction);
    if (along < 0.0) force -= along * direction;
  }
  return force;
}

}  // namespace fahr::device
