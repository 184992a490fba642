// Wire (idl) <-> Eigen and library types of the haptic service. Writes into
// preallocated samples: nothing allocates once sequences hold their
// capacity (reserved at set-up).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <span>

#include "contact_set.h"
#include "device_pose.h"
#include "fahr/contact/force_output.h"
#include "fahr/fem/contact_set.h"
#include "force_command.h"

namespace fahr::haptic_service {

inline Eigen::Vector3d to_eigen(const msg::Vec3& v) {
  return {v.x(), v.y(), v.z()};
}

inline void put(const Eigen::Vector3d& v, msg::Vec3& out) {
  out.x(v.x());
  out.y(v.y());
  out.z(v.z());
}

// Normalised; identity if the wire quaternion is degenerate.
Eigen::Quaterniond to_eigen(const msg::Quat& q);

void put(const Eigen::Quaterniond& q, msg::Quat& out);

void fill_command(const contact::ForceOutput& output, std::uint32_t device_id,
                  msg::ForceCommand& out);

// Contacts in the response's order. Tool contacts name `tool_body_id`;
// obstacle contacts take their body from `obstacle_body_ids`, in order (the
// response copies the tissue-obstacle contacts after the tool's).
void fill_contacts(std::span<const fem::Contact> contacts, std::uint32_t tool_body_id,
                   std::span<const std::uint32_t> obstacle_body_ids, msg::ContactSet& out);

}  // namespace fahr::haptic_service
