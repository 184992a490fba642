// The property runs: lockstep runs on the ~500-tet block with a
// random, bounded device trajectory each (fixed seed per run index), checked
// for: never NaN, never a force above the limit (the ForceCommand's force
// against what the device can render, and the tissue reaction), never a
// persistent penetration of an active constraint. Shared by
// tests/contact/property_test.cpp (1,000 runs) and `contact_bench property`
// (10,000). Every run starts from rest, so a run's outcome depends on its
// index only: any run can be rerun alone, in any order or thread.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "fahr/contact/sim/scenes.h"

namespace fahr::contact::sim {

struct PropertyLimits {
  // An active constraint left penetrating by more than this after the FEM's
  // projection (m) for more than `persistent_steps` consecutive FEM steps is
  // a failure: 10 um is 10x the projection tolerance.
  double penetration_tolerance_m = 1e-5;
  int persistent_steps = 2;
  // The tissue reaction while lost track may exceed the limit by what one
  // tick's FEM update adds (the targets' 5 %).
  double reaction_slack = 1.05;
  // The ForceCommand's force may exceed the limit by rounding only.
  double command_slack = 1.0 + 1e-9;
};

struct PropertyRunResult {
  int run = 0;
  std::uint64_t seed = 0;
  double limit_n = 0.0;         // renderable force of the run, N
  bool finite = true;           // no NaN or infinity in force, proxy or FEM
  bool froze = false;           // lost track at least once
  double max_reaction_n = 0.0;  // largest tissue reaction, N
  double max_command_n = 0.0;   // largest |ForceCommand force|, N
  // Largest penetration an active constraint kept for more than
  // persistent_steps consecutive FEM steps (the smallest depth over such a
  // window), m; 0 when none lasted.
  double max_persistent_penetration_m = 0.0;
  // Largest penetration of a force-only tool contact (TickRecord), m:
  // reported, not a property (no constraint keeps it out).
  double max_force_only_penetration_m = 0.0;
  std::string failure;  // the first property broken; empty when all held
  bool ok() const { return failure.empty(); }
};

// The scene of every run, one per FEM rate (the step size is fixed when a
// body is created); each run resets the one it uses to rest.
class PropertyScenes {
 public:
  // Empty `error` on success.
  explicit PropertyScenes(std::string& error);
  SmallScene& for_run(int run) { return run % 2 == 1 ? slow_ : fast_; }

 private:
  SmallScene fast_;  // FEM at 200 Hz
  SmallScene slow_;  // FEM at 50 Hz
};

inline constexpr double kPropertyRunSeconds = 2.0;

std::uint64_t property_seed(int run);

PropertyRunResult run_property(int run, double seconds, PropertyScenes& scenes,
                               const PropertyLimits& limits = {});

}  // namespace fahr::contact::sim
