// The FEM service's guard on the sphere layout a ContactSet refers to. Its
// sphere ids index the haptic service's AIST; the FEM service fills its own
// from the same scene (fem_body_setup.h) and, with equal scenes and
// settings, gets the same layout, so the ids mean the same spheres. A set
// whose layout fingerprint is not this service's own is refused rather than
// applied to the wrong spheres. accept() runs in the step's thread and
// neither allocates nor blocks; the error sentence is made by take_error()
// on another thread (the status reporter) or after the step.
#pragma once

#include <atomic>
#include <cstdint>
#include <string>

namespace fahr::fem_service {

class LayoutCheck {
 public:
  explicit LayoutCheck(std::uint64_t ours) : ours_(ours), last_seen_(ours) {}

  // True when a set with fingerprint `theirs` may be applied. A refusal is
  // counted; a change of the fingerprint refused (a haptic service with
  // another layout, or back to ours and away again) makes a new error.
  bool accept(std::uint64_t theirs);

  std::uint64_t ours() const { return ours_; }
  // ContactSets refused so far.
  std::uint64_t refused() const { return refused_.load(std::memory_order_relaxed); }
  // The error sentence of the newest change, naming both fingerprints in hex,
  // once per change; empty when there was none since the last call. Call
  // from one thread at a time.
  std::string take_error();

  // "ContactSet refused: its sphere layout 0x... is not this FEM service's
  // 0x... ...".
  static std::string mismatch_error(std::uint64_t ours, std::uint64_t theirs);

 private:
  const std::uint64_t ours_;
  std::uint64_t last_seen_;  // the step's thread only
  std::atomic<std::uint64_t> refused_{0};
  std::atomic<std::uint64_t> last_refused_{0};
  std::atomic<std::uint64_t> changes_{0};
  std::uint64_t changes_reported_ = 0;  // take_error's thread only
};

}  // namespace fahr::fem_service
