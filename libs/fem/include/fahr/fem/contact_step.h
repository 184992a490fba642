// One FEM step under the contact contract (docs/design/contact-contract.md:
// which centre, and what the FEM must do with lambda). The FEM service and
// the in-process lockstep harness
// both step their body through this:
//   1. the haptic solve's contact forces (lambda along n, through each
//      sphere's node weights) and the carried Algorithm 1 correction act as
//      external forces in the implicit step: the free motion x_free;
//   2. the compliance W = h^2 J A^-1 J^T of the compliance spheres (reused
//      while the spheres and the factorisation are unchanged: W depends on
//      nothing else) and their free-motion centres c_free = c - W N lambda,
//      the centres without this step's contact forces;
//   3. the active tool contacts on the block's spheres met through W: a
//      change mu of each contact's force, lambda + mu >= 0 and complementary
//      to the contact's gap, with n^T W N mu >= its penetration of the free
//      motion, and every node moved by h^2 A^-1 J^T N mu (the step's own
//      response to those forces, Body::step_motion), so the tissue gives
//      way as a whole instead of the contact spheres' own nodes;
//   4. the Algorithm 1 projection of the ContactSet on that motion (what
//      the linearisation left and the spheres outside the block), written
//      back to the body; the velocity correction (x~ - x_free)/h of steps 3
//      and 4 is carried into the next step as the nodal force
//      m (x~ - x_free)/h^2, so the next right-hand side M (v + dx/h) + h f
//      is exactly Algorithm 1's;
//   5. with obstacles set, the body's own non-penetration of the static
//      anatomy on these positions (obstacle_projection.h), alternated with
//      the ContactSet's projection so the tool cannot press a node into bone;
//      its moves join the same carried correction; the nodes it moved are
//      held by springs along the bone's normal in the next step's A
//      (obstacle_support.h), so the implicit solve and W feel the bone;
//   6. with a volume floor, in steps where the blade (or a load) presses, each
//      round of that alternation also keeps every tet above a share of its
//      rest volume (volume_floor.h), so tissue squeezed between tool and
//      bone gives way sideways, not flat.
// The correction and the projection are done here, not by Body::step,
// because step 2 needs the motion before them. Staleness of a ContactSet is the caller's decision.
// Capacities are fixed at construction: nothing allocates per step once the
// compliance block and the contact list have reached their largest size.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "fahr/fem/body.h"
#include "fahr/fem/contact_set.h"
#include "fahr/fem/obstacle_field.h"
#include "fahr/fem/obstacle_projection.h"
#include "fahr/fem/obstacle_support.h"
#include "fahr/fem/projection.h"
#include "fahr/fem/sphere_links.h"
#include "fahr/fem/volume_floor.h"

namespace fahr::fem {

struct ContactStepSettings {
  // Apply the ContactSet's lambda as external forces before the projection.
  // false: the projection alone, as Algorithm 1 is written; its fixed point
  // displaces only the constrained spheres' nodes when the step is
  // quasi-static (docs/design/contact-contract.md), kept for that comparison.
  bool apply_contact_forces = true;
  // Spheres in the compliance block at most (a DeformationState carries 64).
  std::size_t max_compliance_spheres = 64;
  // W along each sphere's normal in the ContactSet, one column a sphere
  // ((3k x k), Body::compliance_along), instead of 3x3 blocks: the same
  // solves buy three times the spheres. Ignored with fixed spheres (they
  // have no normals before a set names them).
  bool compliance_along_normals = false;
  // A step that leaves some node non-finite or farther than this from its
  // rest position has diverged (no tissue deforms by more than its size):
  // the body is reset to rest, its carried correction and forces dropped,
  // and the step reports diverged_reset. 0: no check.
  double divergence_limit_m = 0.0;
  // A floor under every tet's volume, projected in each round between the
  // tool's constraints and the anatomy's while the blade or an external load
  // presses the body (volume_floor.h); ratio 0: off.
  VolumeFloorSettings volume_floor{};
};

class ContactStep {
 public:
  // `body` and `links` must outlive this object; the links are the spheres
  // the ContactSets refer to.
  ContactStep(Body& body, const SphereLinks& links, const ContactStepSettings& settings = {});

  // Fixes the compliance spheres, in this order, whatever the ContactSets
  // name (a test surface whose candidates are all known), and computes W now
  // so a contact solve has it before the first step. Without a call the
  // block follows each step's ContactSet: its distinct spheres in order, up
  // to the capacity. Allocates: call at set-up. False (and no block) if a
  // sphere is unknown, there are more than the capacity, or the solve fails.
  bool fix_compliance_spheres(std::span<const std::uint32_t> spheres);

  // The static anatomy (fields in the body's frame, each outliving this
  // object) the body keeps out of by itself in every step, ContactSet or
  // not; the ContactSet's kObstacle entries are then not projected.
  // Allocates: call at set-up.
  void set_obstacles(std::span<const ObstacleField* const> fields,
                     const ObstacleProjectionSettings& settings = {});

  // One step. `contacts` may be null (no usable ContactSet); `extra_forces_n`
  // (3 per node, N, empty for none) acts in this step only (the penalty
  // baseline's forces).
  StepReport step(const ContactSet* contacts, std::span<const double> extra_forces_n = {});

  // After the caller reset the body (Body::reset_to_rest): forgets the
  // carried correction and the applied forces, and solves a fixed block
  // again on the body's new factorisation. False if that solve fails.
  bool reset();

  // The compliance spheres of the newest step, their W (row-major 3k x 3k,
  // m/N; along normals: 3k x k, see compliance_normals()) and free-motion
  // centres (one per sphere, m).
  std::span<const std::uint32_t> compliance_spheres() const { return spheres_; }
  std::span<const float> compliance() const { return compliance_; }
  // With compliance_along_normals: the normal each column of W is along (the
  // ContactSet's, a resultant where a sphere had two pushing contacts);
  // empty for the 3x3 blocks.
  std::span<const Eigen::Vector3d> compliance_normals() const {
    return along_normals() ? std::span<const Eigen::Vector3d>(normals_)
                           : std::span<const Eigen::Vector3d>();
  }
  std::span<const Eigen::Vector3d> free_centres() const { return free_centres_; }
  // Positions after the implicit step, before the projection (3 per node, m).
  std::span<const double> free_positions_m() const { return free_positions_; }
  const ProjectionReport& projection() const { return projection_; }
  // The newest step's push on the tissue from the tool, N: the tool and
  // force-only contacts' applied forces plus the tool projection's moves
  // over h^2 (projection().tool_push_kg_m / h^2). Its length is the
  // reaction on the held tool as the FEM sees it, whatever the haptic side
  // meant to send.
  Eigen::Vector3d tool_reaction_n() const { return tool_reaction_n_; }
  // Steps that reused the previous block, and blocks solved.
  std::uint64_t compliance_reuses() const { return compliance_reuses_; }
  std::uint64_t compliance_solves() const { return compliance_solves_; }

 private:
  void collect(const ContactSet* contacts);
  void add_sphere_force(const Contact& contact);
  void apply_forces(std::span<const double> extra_forces_n);
  void update_compliance(bool refactorised);
  bool along_normals() const { return settings_.compliance_along_normals && !fixed_spheres_; }
  void update_free_centres();
  bool diverged() const;
  // The ContactSet's projection (may be null) and the anatomy's, then the
  // positions and the carried correction written back.
  void project(const ContactSet* contacts);
  void alternate_with_anatomy(const ContactSet* contacts);
  void correct_through_compliance(const ContactSet* contacts);

  Body& body_;
  const SphereLinks& links_;
  ContactStepSettings settings_;
  bool fixed_spheres_ = false;
  std::vector<double> carry_n_;          // carried Algorithm 1 correction, N per DOF
  std::vector<double> force_n_;          // this step's contact and carried force, N per DOF
  std::vector<double> free_positions_;   // x_free, m per DOF
  std::vector<double> projected_;        // projection workspace, m per DOF
  std::vector<double> start_positions_;  // x^n, where the step started, m per DOF
  std::vector<std::uint32_t> spheres_;
  std::vector<std::int32_t> slot_of_sphere_;  // fixed spheres: index in spheres_, or -1
  // Contact force applied per compliance sphere: magnitude along a unit
  // normal (several contacts on one sphere are summed into one vector).
  std::vector<double> lambda_n_;
  std::vector<Eigen::Vector3d> normals_;
  std::vector<float> compliance_;
  std::vector<std::uint32_t> compliance_of_;  // spheres the block was solved for
  std::vector<Eigen::Vector3d> normals_of_;   // and, along normals, their normals
  bool compliance_valid_ = false;
  std::uint64_t compliance_reuses_ = 0;
  std::uint64_t compliance_solves_ = 0;
  std::vector<Eigen::Vector3d> free_centres_;
  // correct_through_compliance(): its rows (a tool contact on a block
  // sphere each), their gaps, normals and block slots, n_i^T W_ij n_j, the
  // impulses found, the nodal force and the motion it gives.
  std::vector<std::size_t> correction_slot_;
  std::vector<Eigen::Vector3d> correction_normal_;
  std::vector<double> correction_gap_m_;
  std::vector<double> correction_w_;
  std::vector<double> correction_mu_;
  std::vector<double> correction_pushed_n_;  // each row's lambda from the ContactSet
  std::vector<double> correction_force_n_;
  std::vector<double> correction_dx_m_;
  Eigen::Vector3d compliance_push_kg_m_ = Eigen::Vector3d::Zero();
  ProjectionSettings projection_settings_;
  std::unique_ptr<ObstacleProjection> obstacles_;
  // With obstacles_ or volume_floor_, and a ratio > 0.
  std::unique_ptr<ObstacleSupport> supports_;
  double support_ratio_ = 0.0;
  std::unique_ptr<VolumeFloor> volume_floor_;  // with a floor ratio > 0
  bool external_load_ = false;                 // this step's extra forces are not all 0
  bool floor_in_force_ = false;                // the floor's pass ran in this step
  ProjectionReport projection_;
  Eigen::Vector3d tool_force_n_ = Eigen::Vector3d::Zero();  // this step's applied tool forces
  Eigen::Vector3d tool_reaction_n_ = Eigen::Vector3d::Zero();
};

}  // namespace fahr::fem
