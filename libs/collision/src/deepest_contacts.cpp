// The k deepest of a query's contacts (see deepest_contacts.h).
#include "fahr/collision/deepest_contacts.h"

#include <algorithm>
#include <numeric>

namespace fahr::collision {

std::size_t select_deepest(const ContactBuffer& contacts, std::size_t keep,
                           std::vector<std::uint32_t>& order) noexcept {
  const std::size_t n = std::min(contacts.size(), order.size());
  std::iota(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(n), 0u);
  if (n <= keep) return n;
  std::partial_sort(
      order.begin(), order.begin() + static_cast<std::ptrdiff_t>(keep),
      order.begin() + static_cast<std::ptrdiff_t>(n),
      [&](std::uint32_t a, std::uint32_t b) { return contacts[a].depth_m > contacts[b].depth_m; });
  return keep;
}

}  // namespace fahr::collision
