// The library-side view of the haptic-to-FEM contact contract
// (docs/design/contact-contract.md): absolute constraints, not deltas.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace fahr::fem {

enum class ContactKind : std::uint8_t {
  kTool,      // force-aware: active or frozen as the haptic side decides
  kObstacle,  // palate, jaw: always a hard non-penetration constraint
  // force_n along n, never projected: the penalty baseline's tool (Figure
  // 7a), and a force-aware tool wedged past the limit (libs/contact).
  kForceOnly,
};

enum class ContactState : std::uint8_t {
  kActive,     // (c' - q) . n >= r
  kFrozen,     // c' = c, where the step found it (projection.h)
  kCandidate,  // near, not touching: only its compliance is wanted
};

struct Contact {
  std::uint32_t sphere_id = 0;  // index into SphereLinks
  ContactKind kind = ContactKind::kTool;
  ContactState state = ContactState::kCandidate;
  // Contact plane: the nearest point of the rigid surface, m (body frame),
  // and the unit normal pointing from that surface toward the sphere centre.
  Eigen::Vector3d plane_point_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::UnitY();
  // The haptic side's estimate of where the tool holds a frozen sphere, m;
  // carried on the wire and reported only: the FEM holds a frozen sphere
  // where its step started (docs/design/retired-modes.md, the hold centre).
  Eigen::Vector3d hold_centre_m = Eigen::Vector3d::Zero();
  double penetration_m = 0.0;  // as the haptic side saw it, m (reported only)
  double force_n = 0.0;        // contact force lambda the haptic solve found, N
};

struct ContactSet {
  // The FEM step whose state the haptic side used.
  std::uint64_t state_step = 0;
  // The body's step when the set arrived (0: when it was computed, i.e.
  // state_step). A set is stale, ignored and counted, once both are more
  // than the body's maximum age (in steps) behind: its planes are where the
  // tool was when it was sent, whatever state it was computed on, so a set
  // that answers an older state but is the sender's newest is applied
  // (a late snapshot on the haptic side must not take the tool off the
  // tongue); only a silent sender's last set runs out.
  std::uint64_t received_step = 0;
  std::vector<Contact> contacts;  // projected in this order
};

}  // namespace fahr::fem
