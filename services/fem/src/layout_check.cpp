// Refusing ContactSets of another sphere layout (see layout_check.h).
#include "fahr/fem_service/layout_check.h"

#include <cstdio>

namespace fahr::fem_service {

bool LayoutCheck::accept(std::uint64_t theirs) {
  const bool changed = theirs != last_seen_;
  last_seen_ = theirs;
  if (theirs == ours_) return true;
  refused_.fetch_add(1, std::memory_order_relaxed);
  if (changed) {
    last_refused_.store(theirs, std::memory_order_relaxed);
    changes_.fetch_add(1, std::memory_order_release);
  }
  return false;
}

std::string LayoutCheck::take_error() {
  const std::uint64_t changes = changes_.load(std::memory_order_acquire);
  if (changes == changes_reported_) return {};
  changes_reported_ = changes;
  return mismatch_error(ours_, last_refused_.load(std::memory_order_relaxed));
}

std::string LayoutCheck::mismatch_error(std::uint64_t ours, std::uint64_t theirs) {
  char text[200];
  std::snprintf(text, sizeof(text),
                "ContactSet refused: its sphere layout fingerprint 0x%016llx is not this FEM "
                "service's 0x%016llx (another scene or aist settings?); its contacts are not "
                "applied",
                static_cast<unsigned long long>(theirs), static_cast<unsigned long long>(ours));
  return text;
}

}  // namespace fahr::fem_service
