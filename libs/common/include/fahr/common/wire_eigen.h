// The topic types' vectors, quaternions and matrices (idl common.idl) to and
// from Eigen: the one set of conversions every service and harness uses.
// Copies into existing samples; nothing allocates.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common.h"

namespace fahr::common {

inline Eigen::Vector3d to_eigen(const msg::Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

inline void put(const Eigen::Vector3d& v, msg::Vec3& out) {
  out.x(v.x());
  out.y(v.y());
  out.z(v.z());
}

// The wire quaternion as sent, not normalised (a receiver that needs a
// rotation checks or normalises it; to_unit_quaternion does both).
inline Eigen::Quaterniond to_eigen(const msg::Quat& q) {
  return {q.w(), q.x(), q.y(), q.z()};
}

// Normalised; identity when the wire quaternion is degenerate (norm zero,
// below 1e-9 or not finite), so a bad sender gives no rotation rather than
// NaN poses downstream.
Eigen::Quaterniond to_unit_quaternion(const msg::Quat& q);

inline void put(const Eigen::Quaterniond& q, msg::Quat& out) {
  out.w(q.w());
  out.x(q.x());
  out.y(q.y());
  out.z(q.z());
}

// Mat3 is row-major.
inline Eigen::Matrix3d to_eigen(const msg::Mat3& m) {
  Eigen::Matrix3d out;
  for (int i = 0; i < 9; ++i) out(i / 3, i % 3) = m.m()[static_cast<std::size_t>(i)];
  return out;
}

inline void put(const Eigen::Matrix3d& m, msg::Mat3& out) {
  for (int i = 0; i < 9; ++i) out.m()[static_cast<std::size_t>(i)] = m(i / 3, i % 3);
}

}  // namespace fahr::common
