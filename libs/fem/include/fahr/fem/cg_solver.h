// Preconditioned conjugate gradients on the assembled system, warm-started,
// with a tolerance and an iteration budget, on preallocated vectors.
//
// Eigen's ConjugateGradient is the same algorithm but declares its residual
// and search vectors inside every solve (heap allocation per step), so fahr
// keeps its own loop with work vectors sized once.
#pragma once

#include <Eigen/Core>
#include <span>

#include "fahr/fem/assembly.h"
#include "fahr/fem/cholmod_solver.h"
#include "fahr/fem/warped_factor.h"

namespace fahr::fem {

enum class CgPreconditioner {
  kJacobi,          // inverse diagonal of A
  kLaggedCholesky,  // a CHOLMOD factorisation of an earlier A
};

struct CgResult {
  int iterations = 0;
  double relative_residual = 0.0;  // |b - A x| / |b|, dimensionless
  bool converged = false;
};

class CgSolver {
 public:
  void resize(std::size_t dofs);

  // Solves A x = b; x holds the initial guess on entry. Stops when
  // |b - A x| <= relative_tolerance |b| or after max_iterations. `factor`
  // (with its warp) is used with kLaggedCholesky and must be factorised.
  // No allocation.
  CgResult solve(const SparseMatrix& a, std::span<const int> diagonal_index,
                 std::span<const double> b, std::span<double> x, double relative_tolerance,
                 int max_iterations, CgPreconditioner preconditioner, CholmodSolver* factor,
                 WarpedFactor* warp);

 private:
  void apply_preconditioner(CgPreconditioner preconditioner, CholmodSolver* factor,
                            WarpedFactor* warp);

  Eigen::VectorXd r_, z_, p_, q_, inverse_diagonal_;
};

// y = A x for a matrix with both triangles stored (rows gathered per column,
// which for a symmetric matrix is the row). No allocation.
void multiply_symmetric(const SparseMatrix& a, const double* x, double* y);

}  // namespace fahr::fem
