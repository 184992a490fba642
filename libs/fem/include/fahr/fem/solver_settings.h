// Settings of the linear solve inside the implicit Euler step.
#pragma once

#include "fahr/fem/cg_solver.h"

namespace fahr::fem {

enum class LinearSolver {
  kCholmod,            // direct, on a factorisation of A (current or lagged)
  kConjugateGradient,  // iterative, on the current A, warm-started from v
};

// When a background factorisation replaces the factor in use
// (SolverSettings::factor_install).
enum class FactorInstall { kWait, kWhenDone };

struct SolverSettings {
  LinearSolver kind = LinearSolver::kCholmod;
  // Steps between numeric refactorisations of A (for kCholmod the solve, for
  // CG the lagged-Cholesky preconditioner and the compliance factor).
  // 1: every step, the exact linearised implicit Euler step.
  // N > 1: the factorisation of an earlier A is reused for N steps.
  // 0: only the rest matrix, factorised once at set-up.
  // Reusing a factorisation changes the dynamics (the Jacobian is lagged) but
  // not the static equilibrium, because the force is always exact.
  int refactor_period = 1;
  // Also refactorise when some element has rotated by more than this since
  // the last factorisation, rad (0 disables). A factorisation is only wrong
  // by the rotation of the material (the material is linear in its rotated
  // frame), so this is "factorise when the matrix changes": 0.1 rad (6
  // degrees) keeps the lagged Jacobian close enough that the step stays
  // damped (a never-refreshed factor oscillates at 45 degrees), while a
  // body deforming gently refactorises rarely.
  double refactor_rotation_rad = 0.1;
  // Also refactorise when some element's compression-stiffening scale
  // (compression_stiffening.h) has changed by more than this fraction of
  // itself since the last factorisation (0 disables; only a material with
  // stiffening has scales that change). Its block of A is off by that
  // fraction, as a turn of 0.1 rad puts it off by about 10 %: 0.1 matches
  // the rotation trigger. Applies where the rotation trigger does (a factor
  // in use and refactor_period != 1).
  double refactor_stiffening_change = 0.1;
  // With the Stable Neo-Hookean material (whose tangent depends on the
  // whole F, not on a rotation): also refactorise when some element's
  // deformation gradient has changed by more than this (Frobenius norm,
  // dimensionless) since the last factorisation (0 disables). 0.1 is a turn
  // of 0.07 rad (a turn of 0.1 rad changes F by 2 sqrt 2 sin(0.05) = 0.141)
  // or a 10 % change of stretch; the SNH tangent is smooth in F, so its
  // blocks are then off by about that fraction, more where the Yeoh term
  // stiffens a compressed element, whose strain the criterion sees: a
  // compressing tongue does not run long on a tangent much softer than the
  // truth. A choice: in the 20 s overshoot run 0.1 refactorised 3,431 times
  // (the corotational tongue 2,604) and let 1 node back through a bone;
  // 0.14 refactorised 2,187 times and let 90 back (fahr_stack_sim_run
  // --script overshoot). Applies where the rotation trigger does.
  double refactor_deformation_change = 0.1;
  // With the Stable Neo-Hookean material, when A is assembled: an element
  // whose F has changed by at most this (Frobenius norm) since its tangent
  // was last computed keeps that tangent, so a refresh recomputes only the
  // elements that moved (0: every element every time). 0.01 lags a block by
  // about 1 %, a tenth of what the refresh trigger allows. The force is
  // exact every step either way, so the equilibrium does not depend on it.
  double tangent_reuse_change = 0.01;
  // A refactorisation the triggers above ask for runs on a thread of its
  // own, from A as assembled at that step, and replaces the factor in use
  // this long after (rounded up to whole steps), the step waiting for it
  // then if it is not done: the step never pays a factorisation, and the
  // same inputs give the same bits however fast the thread was (lockstep).
  // The factor in use is then older by this latency; the force is exact
  // every step, so the equilibrium does not depend on it. 0: the
  // factorisation runs inside the step that asks for it. Ignored with
  // refactor_period 1 (the exact step).
  double background_factor_latency_s = 0.0;
  // What a step does when the background factorisation is due (the
  // latency has passed) and not done yet. kWait: waits for it, so the step
  // it replaces the factor in does not depend on the thread's speed and
  // the same inputs give the same bits (lockstep, tests, benches). kWhenDone:
  // goes on with the factor before and replaces it at the first later step
  // that finds it done, waiting only once ten latencies' worth of steps went
  // on without it, so the factor in use lags by at most eleven latencies
  // (real time: no step waits on a factorisation unless the machine starves
  // its thread, docs/design/fem-step-and-solvers.md). On a machine fast
  // enough for the latency the two are the same.
  FactorInstall factor_install = FactorInstall::kWait;
  // Rotate a reused factorisation per node into the current frame (see
  // warped_factor.h). Off only to measure what it buys.
  bool warp_lagged_factor = false;
  // Factor kind and fill-reducing ordering of the CHOLMOD factorisation.
  CholmodOptions cholmod;
  CgPreconditioner preconditioner = CgPreconditioner::kJacobi;
  // |b - A v| <= tolerance |b|: 1e-6 makes the velocity error far below the
  // per-step change at haptic rates; looser budgets are benchmarked.
  double cg_relative_tolerance = 1e-6;
  int cg_max_iterations = 100;
  // kConjugateGradient with kLaggedCholesky: the lagged factorisation is
  // refreshed (in the next step) after a solve that took more than this many
  // iterations or did not converge, >= 0; 0: only the period and the
  // rotation trigger refresh it. The iteration count is the direct measure
  // of how far the factor has drifted from the current A, so with the
  // rotation trigger off (0) the factor is refreshed only when the solve
  // actually got expensive, not whenever a sliver turned 0.1 rad.
  int cg_refresh_iterations = 0;
};

}  // namespace fahr::fem
