// The k deepest of a query's contacts: what the haptic tick keeps as rows
// when the tool touches more spheres than the contact solve takes. With
// QuerySettings::defer_outside_contacts the query leaves most contacts
// without point and normal; the caller selects here on the depth alone and
// then completes only the kept ones (complete_deferred, sphere_query.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "fahr/collision/contact_buffer.h"

namespace fahr::collision {

// Puts indices of `contacts` in order[0, kept): all of them in buffer order
// when there are at most `keep`, else the `keep` deepest, deepest first (a
// partial sort: among equal depths the pick follows the buffer's order and
// no more). Returns kept; `order` must hold contacts.size() entries.
// Allocation-free.
std::size_t select_deepest(const ContactBuffer& contacts, std::size_t keep,
                           std::vector<std::uint32_t>& order) noexcept;

}  // namespace fahr::collision
