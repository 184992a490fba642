// Contact compliance W = h^2 J A^-1 J^T of candidate spheres
// (docs/design/contact-contract.md): how far sphere centres move in one step per
// newton of force on them, with the tissue's inertia, damping and stiffness.
//
// The solved columns A^-1 J_s^T of each sphere are kept, tagged with the
// factorisation they came from: a sphere that joins the block costs its
// three columns and the others cost nothing, instead of the whole block
// being solved again whenever the set of spheres changes (on the neonatal
// tongue it changes in most steps while the blade slides). After a
// refactorisation the kept columns are those of the one before (a lagged
// factor is refreshed when an element turned 0.1 rad: W from the previous
// one differs by about that much); a budget of spheres a call
// (refresh_per_call) is solved again on the new factor, so a
// refactorisation costs no burst of solves for the whole block: half of
// the budget goes to the first stale spheres in request order (the rows
// the tick solved, the deepest first), the rest to the stalest, so no
// column lags without bound.
//
// A background factorisation brings the block along: when it begins, the
// spheres of the last request are listed, its thread solves their columns
// and products again on the new factor once it is made, and the install
// takes them with it (begin_refresh, refresh_on, adopt_refresh), so the
// block the tick solves on is that of the factor in use, not of the ones
// before, at no cost to the step. Spheres that joined meanwhile are
// refreshed by the budget.
//
// With a supernodal LL' factor (the tongue's) a sphere's columns are the
// half solve Y_s = L^-1 P J_s^T, on the supernodes its DOFs reach only, and
// W_st = h^2 Y_s^T Y_t, summed over the supernodes both reach (the paths to
// the root they share): no backward solve, and a forward solve over a
// fraction of L. Other factors (simplicial, warped) keep full solves
// X_s = A^-1 J_s^T and W_st = h^2 J_s X_t.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "fahr/fem/cholmod_solver.h"
#include "fahr/fem/sphere_links.h"
#include "fahr/fem/warped_factor.h"

namespace fahr::fem {

class ComplianceBlock {
 public:
  // Sizes the cache and the right-hand sides for up to max_spheres
  // candidates. Allocates.
  void reserve(std::size_t dofs, std::size_t max_spheres);
  // After the factor's analysis: room for the panel solves of a full block
  // on its supernodes (set-up: it allocates).
  void reserve_panels(const CholmodSolver& factor) {
    factor.reserve_panels(step_work_, max_spheres_);
    factor.reserve_panels(pending_work_, max_spheres_);
  }
  std::size_t capacity() const { return max_spheres_; }
  // Spheres whose kept columns are solved again on a newer factorisation
  // per compute() call, half of them the first in the request, the others
  // the stalest (default 4); 0: never (columns of a
  // sphere stay those of its first solve while it stays in the block).
  void set_refresh_per_call(std::size_t spheres) { refresh_per_call_ = spheres; }
  // The most factorisations a block's columns lagged behind since the last
  // call of this (then reset): what the refresh budget left.
  std::uint64_t take_oldest_lag() {
    const std::uint64_t lag = oldest_lag_;
    oldest_lag_ = 0;
    return lag;
  }

  // The refresh on the factorisation's thread (supernodal factors only).
  // begin_refresh(), on the step's thread just before a background
  // factorisation begins, lists the spheres of the last compute() whose
  // columns are half solves; `links` and `fixed_dof` must stay unchanged
  // until the refresh is adopted or dropped. Returns how many it listed.
  // refresh_on(), on the factorisation's thread once the new factor is
  // made (CholmodSolver::AfterFactor), solves their columns and products
  // into buffers the step does not read. adopt_refresh(), on the step's
  // thread right after the install, makes them the kept columns, tagged
  // with the installed factorisation, for the spheres still in their
  // slots; drop_refresh() when the factorisation was cancelled or failed.
  // No allocation.
  std::size_t begin_refresh(const SphereLinks& links, std::span<const std::uint8_t> fixed_dof);
  void refresh_on(CholmodSolver::NewFactor& factor);
  void adopt_refresh(const CholmodSolver& factor);
  void drop_refresh() { pending_count_ = 0; }
  // Spheres adopted from the factorisation's thread so far.
  std::uint64_t adopted_refreshes() const { return adopted_; }

  // Writes W, (3k x 3k) row-major float, m/N, for the k spheres listed, from
  // `factor` (a factorisation of A = M + h D + h^2 K, kg), solving only the
  // spheres without columns from this factorisation (all of them when the
  // factor is warped: its rotations change every step). J has three rows per
  // sphere, holding the weights w_i on the x, y and z DOFs of its free nodes
  // (fixed DOFs do not move). Returns false if k exceeds the capacity, `out`
  // is too small, a sphere is unknown, or the factor is missing. Block (s, t) is the motion of
  // sphere s per unit force on sphere t. No allocation (CHOLMOD's solve buffers are kept per chunk
  // size).
  bool compute(std::span<const std::uint32_t> spheres, const SphereLinks& links,
               std::span<const std::uint8_t> fixed_dof, CholmodSolver& factor, WarpedFactor& warp,
               double time_step_s, std::span<float> out);

  // W along given normals, one column a sphere: writes (3k x k) row-major
  // float, m/N, entry (3s + d, t) = (W_st n_t)_d, how sphere s moves per
  // newton on sphere t along n_t (unit normals, one per sphere). A solve
  // per sphere where the 3x3 blocks take three: what a contact solve needs
  // (n_s . W_st n_t) for a third of the solves, if it uses these normals.
  // Nothing is kept between calls. Same failures as compute(); no
  // allocation.
  bool compute_along(std::span<const std::uint32_t> spheres,
                     std::span<const Eigen::Vector3d> normals, const SphereLinks& links,
                     std::span<const std::uint8_t> fixed_dof, CholmodSolver& factor,
                     WarpedFactor& warp, double time_step_s, std::span<float> out);

 private:
  struct Slot {
    std::uint32_t sphere = 0;
    std::uint64_t factorisation = 0;  // CholmodSolver::factorisations() when solved
    std::uint64_t last_use = 0;
    bool valid = false;
    std::size_t reach = 0;  // supernodes of its half solve (reaches_), 0 for full solves
  };
  // The slot holding this sphere's columns for the given factorisation, or
  // a free (least recently used, not in this request) slot marked for it.
  std::size_t slot_for(std::uint32_t sphere, std::uint64_t factorisation, bool& cached);
  void solve_chunk(std::span<const std::size_t> slots, const SphereLinks& links,
                   std::span<const std::uint8_t> fixed_dof, CholmodSolver& factor,
                   WarpedFactor& warp);
  // The right-hand side P J_s^T of `sphere` on its reach, into the slot's
  // buffer `area` (0 or 1), ready for a forward solve on `factor`; returns
  // the reach's length.
  template <typename Factor>
  std::size_t place_half_into(std::size_t slot, std::size_t area, std::uint32_t sphere,
                              const SphereLinks& links, std::span<const std::uint8_t> fixed_dof,
                              Factor& factor, std::vector<std::uint32_t>& sphere_dofs);
  void solve_halves(const SphereLinks& links, std::span<const std::uint8_t> fixed_dof,
                    CholmodSolver& factor);
  // Y_s^T Y_t of two half-solved slots (row-major 3x3), kept until either
  // is solved again.
  const double* half_product(std::size_t s, std::size_t t, const CholmodSolver& factor);
  // Each slot has two buffers (columns and reach): the one in use
  // (area_[slot]) and the one the factorisation's thread may fill.
  const double* column(std::size_t slot, std::size_t d) const {
    return column_in(slot, area_[slot], d);
  }
  double* column(std::size_t slot, std::size_t d) { return column_in(slot, area_[slot], d); }
  const double* column_in(std::size_t slot, std::size_t area, std::size_t d) const {
    return columns_.data() + dofs_ * (3 * (2 * slot + area) + d);
  }
  double* column_in(std::size_t slot, std::size_t area, std::size_t d) {
    return columns_.data() + dofs_ * (3 * (2 * slot + area) + d);
  }
  const int* reach(std::size_t slot) const { return reach_in(slot, area_[slot]); }
  const int* reach_in(std::size_t slot, std::size_t area) const {
    return reaches_.data() + dofs_ * (2 * slot + area);
  }
  int* reach_in(std::size_t slot, std::size_t area) {
    return reaches_.data() + dofs_ * (2 * slot + area);
  }

  std::size_t dofs_ = 0;
  std::size_t max_spheres_ = 0;
  std::vector<Slot> slots_;
  std::vector<double> columns_;     // 2 x 3 columns of dofs_ per slot
  std::vector<int> reaches_;        // 2 per slot, room for dofs_ supernodes each
  std::vector<std::uint8_t> area_;  // the buffer in use per slot
  // The refresh on the factorisation's thread: the listed slots and their
  // spheres, the reach lengths and products it computed (9 per pair of
  // listed spheres), the links it reads.
  struct Pending {
    std::size_t slot = 0;
    std::uint32_t sphere = 0;
    std::size_t reach = 0;
    bool adopted = false;
  };
  std::vector<Pending> pending_;
  std::size_t pending_count_ = 0;
  std::vector<double> pending_pairs_;
  std::vector<HalfSolveColumns> pending_groups_;  // the pending spheres' columns
  std::vector<double> pending_gram_;              // their products, 3 x pending squared
  PanelWorkspace pending_work_;
  std::vector<HalfSolveColumns> step_groups_;  // the same for the step's own solves
  std::vector<double> step_gram_;
  PanelWorkspace step_work_;
  std::vector<std::uint32_t> pending_sphere_dofs_;
  const SphereLinks* pending_links_ = nullptr;
  std::span<const std::uint8_t> pending_fixed_dof_;
  std::vector<std::size_t> last_request_;  // slots of the last compute(), in request order
  std::size_t last_request_count_ = 0;
  std::uint64_t adopted_ = 0;
  std::vector<std::uint32_t> sphere_dofs_;  // the free DOFs of one sphere
  bool half_ = false;                       // the kept columns are half solves
  std::vector<double> pairs_;               // Y_s^T Y_t per pair of slots, 9 each
  std::vector<std::uint8_t> pair_known_;    // whether pairs_ holds that pair's
  std::vector<std::size_t> request_slots_;  // slot of each requested sphere
  std::vector<std::size_t> to_solve_;       // slots to solve this call
  std::vector<double> rhs_;                 // one chunk of right-hand sides
  std::vector<double> solution_;
  std::uint64_t uses_ = 0;
  std::size_t refresh_per_call_ = 4;
  std::uint64_t oldest_lag_ = 0;
};

}  // namespace fahr::fem
