// The paper's force-aware constraint (section 3.2) as a small state machine:
// tool constraints are active while the tissue reaction stays within the
// force the device can render now; past it they freeze and the device "has
// lost track"; they reactivate, with hysteresis, when the coupling force
// falls back, and the proxy then catches up at a bounded speed.
#pragma once

#include <cstdint>

namespace fahr::contact {

enum class TrackingState : std::uint8_t {
  kTracking,    // tool constraints active, proxy in equilibrium
  kLostTrack,   // tool constraints frozen, proxy held where it was
  kCatchingUp,  // reactivated; the proxy moves to equilibrium at a bounded speed
};

enum class HeldProxy : std::uint8_t {
  // Stays where it froze (the paper's positional hold: the proxy stops,
  // c' = c); the tissue forces sent to the FEM are scaled so that their
  // resultant is the limit, and the spheres stay frozen (the FEM holds them
  // where each step finds them). The published gap is then the hand's pull
  // past the limit. A scene choice (contact.held_proxy: stay).
  kStay,
  // The default. Stays where it froze (the published gap is then exactly
  // the hand's pull past the proxy), and the tissue is held by a load, not
  // by position constraints: each tick's pinned solve at the held pose,
  // scaled so that its resultant is at most the limit, sent as force only
  // (never projected). At equilibrium a position hold's force is that load,
  // so the tissue settles where c' = c would hold it; but a load cannot
  // fight the forces it is sent, as kStay's frozen spheres do (the strain
  // grew under them). It releases, and holds again while catching up, on
  // the hand's pull along the push it froze with, never backs off, and
  // keeps the load scaled and force only while catching up past the limit
  // (docs/design/force-aware-decision.md, the held proxy).
  kHoldLoad,
  // Retired, kept for the overshoot bench's comparison only (bench-only:
  // stack_sim::Experiments::back_off_held_proxy): backs off along the
  // reaction until the reaction is the limit (ContactResponse::
  // yield_to_limit); the proxy drifts from where it froze.
  kBackOff,
};

struct ForceAwareSettings {
  bool enabled = true;  // false: never freeze (naive mode, or a test of the solve alone)
  // Constraints reactivate when the coupling force falls below
  // (1 - hysteresis) x limit, [0, 0.9]. 0.1: a hand's force tremor is a few
  // percent of a newton, so 10 % of ~2 N does not chatter.
  double hysteresis = 0.1;
  // Fastest proxy motion while catching up, m/s, > 0. The stylus force then
  // changes by at most K_c x this x dt per tick beyond what the hand's own
  // motion causes: 0.05 m/s x 400 N/m x 1 ms = 0.02 N per tick, 20 N/s,
  // below the ~ 50 N/s at which a force step is felt as a click.
  double catch_up_speed_mps = 0.05;
  // Fastest change of that motion, m/s^2, > 0: the coupling's damping then
  // changes the stylus force by at most B x this x dt per tick (1 N s/m x
  // 10 m/s^2 x 1 ms = 0.01 N) when the equilibrium the proxy heads for
  // turns (it moves with every FEM state); without it a turn reversed the
  // proxy's velocity in one tick, a 2 B v_c = 0.1 N step. 10 m/s^2 reaches
  // the full catch-up speed in 5 ms.
  double catch_up_acceleration_mps2 = 10.0;
  // What a proxy held while the device has lost track does when the pinned
  // solve's tissue reaction exceeds the limit (the tissue's state changed
  // under it, or the gateway lowered the limit).
  HeldProxy held_proxy = HeldProxy::kHoldLoad;
};

// Tissue reaction past the limit: freeze.
inline bool should_freeze(const ForceAwareSettings& s, double tissue_reaction_n, double limit_n) {
  return s.enabled && tissue_reaction_n > limit_n;
}

// Coupling force (or the tissue reaction tracking again would give) back
// below the hysteresis band: reactivate.
inline bool should_release(const ForceAwareSettings& s, double coupling_force_n, double limit_n) {
  return coupling_force_n < (1.0 - s.hysteresis) * limit_n;
}

}  // namespace fahr::contact
