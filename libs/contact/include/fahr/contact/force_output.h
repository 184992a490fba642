// What a ForceCommand needs from one tick (world frame, SI units).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>

namespace fahr::contact {

struct ForceOutput {
  std::uint64_t answered_pose_seq = 0;                            // DevicePose seq answered
  Eigen::Vector3d answered_position_m = Eigen::Vector3d::Zero();  // x_k, m
  // F_k: force on the stylus at x_k, N, at most the renderable force of the
  // DevicePose answered (force_limit.h); the gateway still scales what it
  // extrapolates to its newer pose.
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
  // K_k = -dF/dx at x_k, N/m, symmetric PSD, <= the coupling stiffness.
  Eigen::Matrix3d stiffness_npm = Eigen::Matrix3d::Zero();
  Eigen::Vector3d proxy_position_m = Eigen::Vector3d::Zero();             // m
  Eigen::Quaterniond proxy_orientation = Eigen::Quaterniond::Identity();  // = the device's
  bool lost_track = false;                                                // tool constraints frozen
  Eigen::Vector3d device_minus_proxy_m = Eigen::Vector3d::Zero();  // m (the paper's grey dummy)
  double tissue_reaction_n = 0.0;     // |sum of tissue contact forces on the tool|, N, >= 0
  std::uint32_t active_contacts = 0;  // rows with lambda > 0
  std::uint64_t fem_step = 0;         // DeformationState step used
};

}  // namespace fahr::contact
