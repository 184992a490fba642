// The DeformationStates of the tissue's bodies (one per deformable body)
// digested for the haptic tick: sphere centres and
// radii, the refitted sphere tree, the compliance W of the candidate spheres
// with their free-motion centres, and the tissue's contacts with the rigid
// anatomy. Built off the tick (TissueDigest, on the state thread in real time
// or inline in lockstep) so the 1 kHz tick only reads it: digesting a state
// costs about a millisecond on the neonatal tongue, the tick's whole budget.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "deformation_state.h"
#include "fahr/collision/contact_buffer.h"
#include "fahr/collision/rigid_body.h"
#include "fahr/collision/sphere_query.h"
#include "fahr/collision/sphere_state.h"
#include "fahr/collision/sphere_tree.h"
#include "fahr/collision/triangle_baseline.h"
#include "fahr/contact/contact_row.h"
#include "fahr/contact/tissue_compliance.h"
#include "fahr/fem/contact_set.h"
#include "fahr/haptic_service/haptic_setup.h"

namespace fahr::haptic_service {

struct TissueSnapshot {
  // false: the rest state the loop starts from, before any DeformationState.
  bool from_fem = false;
  // The first body's DeformationState::step; each body's, in the setup's
  // order (one FEM service steps them together: they differ only while a
  // period's states are still arriving).
  std::uint64_t fem_step = 0;
  std::vector<std::uint64_t> body_fem_steps;
  // DeformationState::reset_epoch summed over the bodies: a reset of any
  // changes it.
  std::uint32_t reset_epoch = 0;
  // The FEM participant that wrote the state (SampleHeader::writer_id): a
  // restarted FEM service is a new writer whose tongue starts at rest.
  std::uint32_t fem_writer = 0;
  collision::SphereState spheres;
  collision::SphereTree tree;

  // W of compliance_ids (3k x 3k row-major, m/N) and their free-motion
  // centres (3k, m; empty when the FEM did not send them). Several bodies:
  // their blocks one after the other, block-diagonal (zero between bodies),
  // ids in the joined layout.
  std::vector<std::uint32_t> compliance_ids;
  std::vector<float> w_mpn;
  std::vector<float> free_centres_m;
  // The FEM's normal of each compliance sphere when W came along normals
  // (DeformationState.compliance_normals).
  std::vector<float> compliance_normals;
  bool have_compliance_normals = false;
  std::size_t compliance_count = 0;
  bool have_free_centres = false;
  // Per sphere id: its index in compliance_ids, or contact::kNoCompliance.
  std::vector<std::int32_t> compliance_index;

  // Tissue spheres pressed into rigid anatomy (always hard constraints),
  // and the body each one touches.
  std::vector<fem::Contact> obstacle_contacts;
  std::vector<std::uint32_t> obstacle_body_ids;
  std::size_t obstacle_count = 0;
  bool obstacle_overflow = false;

  // The triangle baseline's refitted trees (CollisionMethod::kTriangle
  // only): one per snapshot, since the tick reads it while the feed
  // refits another.
  std::unique_ptr<collision::TriangleBaseline> triangles;

  double digest_us = 0.0;  // wall time the digest took, us

  contact::TissueCompliance compliance() const;
  std::span<const fem::Contact> tissue_obstacle_contacts() const {
    return {obstacle_contacts.data(), obstacle_count};
  }
  std::span<const std::uint32_t> tissue_obstacle_body_ids() const {
    return {obstacle_body_ids.data(), obstacle_count};
  }
};

// Turns DeformationStates into snapshots. Owned by one thread at a time;
// digest() allocates nothing once the snapshot's capacities are reserved
// (make_snapshot() reserves them).
class TissueDigest {
 public:
  explicit TissueDigest(const HapticSetup& setup);

  // A snapshot of the tongue at rest, every buffer at full capacity (and
  // its own triangle trees when the setup asks for the baseline).
  TissueSnapshot make_snapshot();

  // Digests the bodies' states, states[b] of HapticSetup::bodies[b], into
  // `out` (whatever it held before). False, with `out` unusable, when one is
  // missing, of another body, does not fit its mesh or holds a non-finite
  // position: the caller keeps its previous snapshot.
  bool digest(std::span<const msg::DeformationState* const> states, TissueSnapshot& out);
  // The one body's state (a scene with one deformable body).
  bool digest(const msg::DeformationState& state, TissueSnapshot& out) {
    const msg::DeformationState* one = &state;
    return digest({&one, 1}, out);
  }

  // Whether `state` can be digested: of one of the bodies, positions for
  // every node of its mesh, every position, compliance entry, normal and
  // free centre finite. Reads nothing digest() writes (a reader's Admission
  // calls it on the vendor thread).
  bool plausible(const msg::DeformationState& state) const;

 private:
  void query_obstacles(TissueSnapshot& out);
  void index_compliance(std::span<const msg::DeformationState* const> states, TissueSnapshot& out);
  // The body (index into HapticSetup::bodies) of a state's body_id, or the
  // body count when none.
  std::size_t body_index(std::uint32_t body_id) const;

  const HapticSetup& setup_;
  std::vector<double> positions_m_;  // float wire positions widened for SphereState
  std::vector<collision::RigidBody> obstacle_bodies_;
  std::vector<collision::PrePenetrationMemory> obstacle_memory_;
  collision::QuerySettings obstacle_query_;
  collision::ContactBuffer obstacle_buffer_;
};

}  // namespace fahr::haptic_service
