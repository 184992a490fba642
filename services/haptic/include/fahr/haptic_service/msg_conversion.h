// Library types of the haptic service to the wire (idl); vectors and
// quaternions go through fahr/common/wire_eigen.h. Writes into preallocated
// samples: nothing allocates once sequences hold their capacity (reserved at
// set-up).
#pragma once

#include <cstdint>
#include <span>

#include "contact_set.h"
#include "device_pose.h"
#include "fahr/contact/force_output.h"
#include "fahr/fem/contact_set.h"
#include "force_command.h"

namespace fahr::haptic_service {

void fill_command(const contact::ForceOutput& output, std::uint32_t device_id,
                  msg::ForceCommand& out);

// Contacts in the response's order, then `requests` (tool contacts: the
// tick's compliance requests), up to msg::MAX_CONTACTS in all. Tool contacts
// name `tool_body_id`; obstacle contacts take their body from
// `obstacle_body_ids`, in order (the response copies the tissue-obstacle
// contacts after the tool's).
void fill_contacts(std::span<const fem::Contact> contacts, std::span<const fem::Contact> requests,
                   std::uint32_t tool_body_id, std::span<const std::uint32_t> obstacle_body_ids,
                   msg::ContactSet& out);

}  // namespace fahr::haptic_service
