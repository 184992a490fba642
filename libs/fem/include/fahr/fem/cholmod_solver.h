// Sparse Cholesky on SuiteSparse CHOLMOD: symbolic analysis once, numeric
// factorisation when the values change, solves into preallocated storage.
// A numeric factorisation may also run on a thread of its own while solves
// go on with the factor before it (the asynchronous factorisation of
// Courtecuisse, Allard, Duriez and Cotin, "Asynchronous preconditioners for
// efficient solving of non-linear deformable objects", VRIPHYS 2010); the
// caller decides when the new factor replaces the old one.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "fahr/fem/assembly.h"

namespace fahr::fem {

enum class CholmodFactorKind {
  kAuto,        // CHOLMOD chooses by flop count per non-zero
  kSimplicial,  // LDL': slower to factorise, faster single-vector solves
  kSupernodal,  // LL' with BLAS: fastest factorisation of large 3-D meshes
};

enum class CholmodOrdering {
  kDefault,  // CHOLMOD's own choice (AMD, METIS if AMD fills badly)
  kAmd,      // approximate minimum degree
  kMetis,    // METIS nested dissection: least fill on 3-D meshes
};

// METIS by default: on 3-D tet meshes it leaves 10-15 % fewer non-zeros in
// L than AMD (fem_bench target table), at a higher one-off analysis cost.
struct CholmodOptions {
  CholmodFactorKind factor = CholmodFactorKind::kAuto;
  CholmodOrdering ordering = CholmodOrdering::kMetis;
};

// Three columns of rows() entries each, one after the other at `y`, in the
// factor's ordering, holding P B on the rows of the ascending supernodes
// reach[0, count) (as forward3_on_reach wants them): one sphere's half solve.
struct HalfSolveColumns {
  double* y = nullptr;
  const int* reach = nullptr;
  std::size_t count = 0;
};

// Scratch of forward_gram_on_reach, sized for a count of spheres by
// CholmodSolver::reserve_panels after the analysis (a call for more grows
// it once).
struct PanelWorkspace {
  std::vector<double> panel;  // one supernode's rows of the active columns
  std::vector<double> below;  // their update to the rows below it
  std::vector<double> gram;   // the active columns' products on it
  std::vector<std::size_t> cursor;
  std::vector<std::size_t> active;
};

// The background thread's CPU over its jobs, ns, by part: the caller's
// fill (assembly), the numeric factorisation, the caller's after (W's
// columns on the new factor).
struct BackgroundCpu {
  std::int64_t fill_ns = 0;
  std::int64_t factor_ns = 0;
  std::int64_t after_ns = 0;
  std::uint64_t jobs = 0;
};

class CholmodSolver {
  struct State;

 public:
  // Multi-column solves keep their buffers per column count, for this many
  // counts (the compliance block solves a full block and fixed-size chunks).
  static constexpr std::size_t kColumnCounts = 6;

  CholmodSolver();
  ~CholmodSolver();
  CholmodSolver(const CholmodSolver&) = delete;
  CholmodSolver& operator=(const CholmodSolver&) = delete;

  // Fill-reducing ordering and symbolic factorisation of the pattern of
  // `matrix` (its upper triangle). `matrix` must outlive the solver and keep
  // its pattern; only its values may change. Returns false if CHOLMOD fails.
  bool analyze(const SparseMatrix& matrix, const CholmodOptions& options = {});
  // Numeric factorisation of the current values. False if not positive
  // definite. CHOLMOD allocates internally here (permuted copy, supernodal
  // workspace): call it outside the no-allocation path or accept that.
  bool factorize();
  bool factorized() const;
  // Successful numeric factorisations so far: a solve of a cached right-hand
  // side is still valid while this is unchanged (compliance.h).
  std::uint64_t factorisations() const;

  // x = A^-1 b for the last factorised A; b and x have A.rows() entries and
  // may alias. No allocation after the first call (buffers are kept).
  void solve(std::span<const double> b, std::span<double> x);
  // X = A^-1 B for `columns` right-hand sides, column-major with leading
  // dimension A.rows(). No allocation after the first call with this count
  // while at most kColumnCounts different counts are in use.
  void solve_columns(std::span<const double> b, std::span<double> x, int columns);

  // Background factorisation. enable_background() (set-up: it starts the
  // thread and allocates a second factor and a copy of the values) after
  // analyze(). begin_factorize() copies the matrix's current values and
  // factorises them on the thread; solves meanwhile use the factor before.
  // False if no background is enabled or one is already running.
  // finish_factorize() waits for it and, if the values were positive
  // definite, makes it the factor solves use (a factorisation counted);
  // false if it failed, the factor before then stays. cancel_factorize()
  // waits and throws the result away (before a synchronous factorize()).
  //
  // begin_factorize(fill, context) has the thread write the values itself
  // first: fill(context, values) with one entry per non-zero of the
  // analysed pattern (the caller's assembly, off its own thread); the
  // caller keeps what fill reads unchanged until finish or cancel.
  //
  // begin_factorize(fill, context, after) has the thread go on, once the
  // factorisation succeeded and before finish_factorize() can take it, with
  // after(context, new_factor): sparse forward solves on the new factor
  // (the compliance block solves its spheres' columns again there, so the
  // install brings them along). Same rule as for fill: what it reads and
  // writes is the caller's to leave alone until finish or cancel.
  class NewFactor;
  using FillValues = void (*)(void* context, std::span<double> values);
  using AfterFactor = void (*)(void* context, NewFactor& new_factor);
  bool enable_background();
  bool begin_factorize(FillValues fill = nullptr, void* context = nullptr,
                       AfterFactor after = nullptr);
  bool finish_factorize();
  void cancel_factorize();
  // True when no background factorisation is under way (none begun, or the
  // one begun has ended): finish_factorize() would not wait. Never blocks
  // for longer than the thread's bookkeeping.
  bool background_done() const;
  // CPU time the background thread has used so far, ns (0 without one).
  std::int64_t background_cpu_ns() const;
  // The same by part, over the jobs that have ended.
  BackgroundCpu background_parts() const;

  // Solves with sparse right-hand sides (the compliance block, compliance.h).
  // With a supernodal LL' factor, A = P^T L L^T P, so b^T A^-1 c =
  // (L^-1 P b)^T (L^-1 P c), and L^-1 P b is non-zero only on the supernodes
  // of the elimination tree's paths from b's non-zeros to the root: a few of
  // them, where a dense solve runs over all of L twice.
  //
  // True when the factor in use is a numeric supernodal LL' factor.
  bool sparse_forward_ready() const;
  std::size_t supernodes() const;
  // The position of `dof` in the factor's ordering (the row of P b it lands on).
  int permuted(std::size_t dof) const;
  // The supernodes L^-1 P b reaches for a b with non-zeros at these DOFs,
  // ascending (children before parents), into `out` (room for supernodes());
  // returns their count. No allocation.
  std::size_t reach(std::span<const std::uint32_t> dofs, std::span<int> out);
  // The columns [first, last) of supernode k in the factor's ordering;
  // supernode_bounds()[k] and [k + 1] are the same (the analysis's).
  int supernode_first(int k) const;
  int supernode_end(int k) const;
  const int* supernode_bounds() const;
  // Y := L^-1 Y, in place, for three columns of A.rows() entries each,
  // one after the other in `y`, in the factor's ordering, that hold P B on
  // the rows of the supernodes in `reach` (the caller zeroes those rows
  // before scattering B; other rows are neither read nor written). L is
  // read once for the three. No allocation.
  void forward3_on_reach(std::span<const int> reach, std::span<double> y);
  // x = A^-1 b for a b that is zero but on `dofs` (b and x of A.rows()
  // entries): the forward solve on the supernodes those DOFs reach, the
  // backward solve on all of L. Needs sparse_forward_ready(). The same x
  // as solve() within rounding. No allocation.
  void solve_sparse(std::span<const std::uint32_t> dofs, std::span<const double> b,
                    std::span<double> x);
  // Y := L^-1 Y for several spheres' columns at once, and gram := Y^T Y,
  // row-major, (3 x groups) squared. Each supernode of L is read once for
  // all the groups that reach it, as one dense panel (BLAS level 3: the
  // triangular solve, the update below, the panel's Gram product); a group
  // is zero outside its reach, so the sum over the supernodes a pair shares
  // is the pair's product. The same Y as forward3_on_reach within rounding.
  // No allocation once `work` has grown to the largest count of groups.
  void forward_gram_on_reach(std::span<const HalfSolveColumns> groups, PanelWorkspace& work,
                             std::span<double> gram);
  // Room in `work` for up to `groups` spheres on this analysis's supernodes
  // (set-up: it allocates).
  void reserve_panels(PanelWorkspace& work, std::size_t groups) const;

  // The sparse forward solve above on a background factorisation's new
  // factor, on its thread (AfterFactor), with visit marks and an update
  // buffer of its own: the step's thread meanwhile solves on the factor in
  // use. The supernodes and the ordering are the analysis's, the same for
  // both factors.
  class NewFactor {
   public:
    std::size_t reach(std::span<const std::uint32_t> dofs, std::span<int> out);
    void forward3_on_reach(std::span<const int> reach, std::span<double> y);
    // As CholmodSolver's, on the new factor.
    void forward_gram_on_reach(std::span<const HalfSolveColumns> groups, PanelWorkspace& work,
                               std::span<double> gram);
    int permuted(std::size_t dof) const;
    int supernode_first(int k) const;
    int supernode_end(int k) const;
    const int* supernode_bounds() const;
    // True when the new factor is a numeric supernodal LL' factor.
    bool sparse_forward_ready() const;

   private:
    friend class CholmodSolver;
    explicit NewFactor(State* state) : state_(state) {}
    State* state_;
  };

  // Non-zeros of the factor L, for reports.
  double factor_nonzeros() const;
  bool supernodal() const;

 private:
  std::unique_ptr<State> state_;
};

}  // namespace fahr::fem
