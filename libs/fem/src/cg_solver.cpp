// Preconditioned CG (Hestenes-Stiefel form, as in Saad, "Iterative Methods
// for Sparse Linear Systems", algorithm 9.1).
#include "fahr/fem/cg_solver.h"

#include <cmath>

namespace fahr::fem {

void multiply_symmetric(const SparseMatrix& a, const double* x, double* y) {
  const int* outer = a.outerIndexPtr();
  const int* inner = a.innerIndexPtr();
  const double* values = a.valuePtr();
  const Eigen::Index n = a.cols();
  for (Eigen::Index j = 0; j < n; ++j) {
    double sum = 0.0;
    for (int k = outer[j]; k < outer[j + 1]; ++k) sum += values[k] * x[inner[k]];
    y[j] = sum;
  }
}

void CgSolver::resize(std::size_t dofs) {
  const auto n = static_cast<Eigen::Index>(dofs);
  r_.setZero(n);
  z_.setZero(n);
  p_.setZero(n);
  q_.setZero(n);
  inverse_diagonal_.setZero(n);
}

void CgSolver::apply_preconditioner(CgPreconditioner preconditioner, CholmodSolver* factor,
                                    WarpedFactor* warp) {
  if (preconditioner == CgPreconditioner::kLaggedCholesky && factor != nullptr && warp != nullptr) {
    warp->solve(*factor, r_.data(), z_.data());
  } else {
    z_ = r_.cwiseProduct(inverse_diagonal_);
  }
}

CgResult CgSolver::solve(const SparseMatrix& a, std::span<const int> diagonal_index,
                         std::span<const double> b, std::span<double> x, double relative_tolerance,
                         int max_iterations, CgPreconditioner preconditioner, CholmodSolver* factor,
                         WarpedFactor* warp) {
  CgResult result;
  const Eigen::Index n = a.rows();
  Eigen::Map<const Eigen::VectorXd> rhs(b.data(), n);
  Eigen::Map<Eigen::VectorXd> sol(x.data(), n);
  if (preconditioner == CgPreconditioner::kJacobi || factor == nullptr) {
    const double* values = a.valuePtr();
    for (Eigen::Index k = 0; k < n; ++k) {
      // The diagonal of M + h D + h^2 K is at least the (positive) mass term.
      inverse_diagonal_[k] = 1.0 / values[diagonal_index[static_cast<std::size_t>(k)]];
    }
  }
  const double rhs_norm = rhs.norm();
  if (!(rhs_norm > 0.0)) {
    // b = 0 has the solution 0 (A is positive definite).
    sol.setZero();
    result.converged = true;
    return result;
  }
  const double threshold = relative_tolerance * rhs_norm;
  multiply_symmetric(a, sol.data(), q_.data());
  r_ = rhs - q_;
  double residual_norm = r_.norm();
  if (residual_norm <= threshold) {
    result.relative_residual = residual_norm / rhs_norm;
    result.converged = true;
    return result;
  }
  apply_preconditioner(preconditioner, factor, warp);
  p_ = z_;
  double rz = r_.dot(z_);
  while (result.iterations < max_iterations) {
    multiply_symmetric(a, p_.data(), q_.data());
    const double pq = p_.dot(q_);
    // pq <= 0 means A is not positive definite along p (or p vanished):
    // continuing would divide by zero or diverge.
    if (!(pq > 0.0)) break;
    const double alpha = rz / pq;
    sol += alpha * p_;
    r_ -= alpha * q_;
    ++result.iterations;
    residual_norm = r_.norm();
    if (residual_norm <= threshold) break;
    apply_preconditioner(preconditioner, factor, warp);
    const double rz_next = r_.dot(z_);
    p_ = z_ + (rz_next / rz) * p_;
    rz = rz_next;
  }
  result.relative_residual = residual_norm / rhs_norm;
  result.converged = residual_norm <= threshold;
  return result;
}

}  // namespace fahr::fem
