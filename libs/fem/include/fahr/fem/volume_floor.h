// A floor under every tet's volume, projected with the step's other
// position constraints (Algorithm 1's Gauss-Seidel): no tet may end a step
// with less than `ratio` of its rest volume.
//
// Why: squeezed between the blade and bone, a soft linear tongue is driven
// flat. The tool's and the anatomy's projections move only the nodes they
// touch, along their own normals, and nothing in them resists a layer of
// tissue being pressed to nothing between the two; the implicit step's
// linearised corotational force, with the large velocities those moves
// carry, then inverts it (docs/design/anatomy-contact.md,
// the volume floor; bench/overshoot). Soft tissue is nearly
// incompressible (the tongue's nu is 0.45): no load the device can apply
// takes a piece of it below half its volume. Projecting the floor gives the
// squeezed layer the way real tissue takes: sideways, out from between the
// two surfaces.
//
// The constraint C = V - ratio V0 >= 0, V the signed volume
// (x1 - x0) . ((x2 - x0) x (x3 - x0)) / 6. A tet below its floor moves its
// nodes along grad V, mass-weighted (the contact projection's rule):
// dx_a = -C w_a g_a / sum_b w_b |g_b|^2, w the inverse nodal mass (0 for a
// fixed node, which never moves). V is cubic in the positions, so one move
// lands near, not on, the floor; sweeps repeat it. Only tets below their
// floor cost more than the volume test.
//
// Only tets that can have changed are tested: a tet found above its floor
// stays above until one of its nodes moves. The pass remembers the
// positions it left and, at its next call, takes every node that moved
// since (the implicit step moves them all; the tool's and the anatomy's
// projections between two passes of one step, a few) as making its tets
// unchecked; a sweep tests only unchecked tets, in index order, and a move
// makes the tets around its nodes unchecked. Each tet is tested exactly when
// a sweep over all of them would have found it changed, so the moves are
// the same, bit for bit, as testing every tet in every sweep.
//
// The floor is a wall that A does not know: the elastic step drives the
// squeezed tissue into it, the pass puts it back, and the moves carried
// into the next step keep the tets around it cycling. So the pass records
// every tet it moved and the direction it opened it along (the gradient of
// its volume over its free nodes), and the step holds each such tet with a
// spring along that direction in A, as it holds a node on bone
// (ObstacleSupport, docs/design/anatomy-contact.md). For a held tet, three
// of whose nodes are fixed (it rests on the body's attachment), that
// spring is a node support of its fourth node along the fixed face's
// normal.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "fahr/fem/element_rest.h"

namespace fahr::fem {

// A tet counts as below its floor under this share of it, while a move aims
// at the floor itself: V is cubic in the positions, so without the slack a
// tet landing a hair under its floor would take every sweep.
inline constexpr double kVolumeFloorSlack = 0.99;

// The signed volume of tet `t` at positions_m (3 per node), m^3; negative
// when inverted.
double signed_volume(std::span<const double> positions_m, const Tet& t);

struct VolumeFloorSettings {
  // Smallest volume a tet may end the step with, as a share of its rest
  // volume, in [0, 1); 0: no floor (no pass at all).
  double ratio = 0.0;
  // Gauss-Seidel sweeps over all tets per pass, >= 1. Between two, up to
  // `inner_sweeps` sweeps over just the tets the last one found below.
  int max_sweeps = 32;
  int inner_sweeps = 8;
};

struct VolumeFloorReport {
  int below = 0;       // tets below their floor when the pass started
  int unresolved = 0;  // still below it after the last sweep
  int sweeps = 0;
};

class VolumeFloor {
 public:
  // `rest` must outlive this object.
  VolumeFloor(const ElementRest& rest, const VolumeFloorSettings& settings);

  // Moves positions_m (3 per node, m) so every tet keeps its floor, as far
  // as the sweeps allow. No allocation.
  VolumeFloorReport project(std::span<double> positions_m,
                            std::span<const double> inverse_mass_per_kg);

  const VolumeFloorSettings& settings() const { return settings_; }

  // Forgets the tets moved in the last step. No allocation.
  void begin_step();
  // Whether a pass since begin_step() moved tet `tet`, and the direction it
  // moved it along the last time: per node, the gradient of its volume,
  // zero on the fixed nodes, the 12 entries of unit length.
  bool moved(std::size_t tet) const { return moved_[tet] != 0; }
  const std::array<Eigen::Vector3d, 4>& direction(std::size_t tet) const { return direction_[tet]; }
  std::size_t tet_count() const { return moved_.size(); }
  const std::vector<Tet>& tets() const { return rest_.tets; }

 private:
  // One tet's move toward its floor; false if it was not below (slack
  // included). A move marks the tets around its nodes unchecked.
  bool open(std::size_t tet, std::span<double> positions_m,
            std::span<const double> inverse_mass_per_kg);
  // Marks unchecked the tets of every node that moved since the last pass.
  void note_moves(std::span<const double> positions_m);
  void mark_around(std::uint32_t node);

  const ElementRest& rest_;
  VolumeFloorSettings settings_;
  std::vector<double> floor_m3_;    // ratio x rest volume, per tet
  std::vector<std::size_t> below_;  // tets the last sweep found below; capacity: every tet
  // The tets of each node (compressed rows: node n's are
  // node_tets_[node_start_[n] .. node_start_[n + 1])).
  std::vector<std::uint32_t> node_start_;
  std::vector<std::uint32_t> node_tets_;
  std::vector<std::uint8_t> unchecked_;  // per tet: to be tested by the next sweep that reaches it
  std::vector<double> last_positions_;   // where the last pass left the nodes; empty before it
  // Per tet (see moved), and the tets marked since begin_step (capacity:
  // every tet, so marking allocates nothing).
  std::vector<std::uint8_t> moved_;
  std::vector<std::array<Eigen::Vector3d, 4>> direction_;
  std::vector<std::uint32_t> moved_tets_;
};

}  // namespace fahr::fem
