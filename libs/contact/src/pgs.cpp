// Projected Gauss-Seidel sweeps in fixed row order.
#include "fahr/contact/pgs.h"

#include <algorithm>
#include <cmath>

#include "fahr/geometry/vector_clones.h"

namespace fahr::contact {

// The residual r = b - S lambda is kept up to date instead of recomputed row
// by row: a row whose lambda does not change (a separated contact that stays
// at 0, the common case) costs one comparison, and a change updates r by
// one column of S (S is symmetric: the row), a loop without a carried
// dependency that the compiler vectorises. Recomputing r_i as a k-long dot
// product per row visit was a serial chain of additions, four times slower
// per row on this machine, and paid for rows that never move.
FAHR_VECTOR_CLONES PgsReport solve_pgs(const double* s, std::size_t stride, std::size_t k,
                                       const double* b, double* lambda, double* residual,
                                       const PgsSettings& settings) {
  PgsReport report;
  if (k == 0) return report;
  for (std::size_t i = 0; i < k; ++i) {
    const double* row = s + i * stride;
    double sum = b[i];
    for (std::size_t j = 0; j < k; ++j) sum -= row[j] * lambda[j];
    residual[i] = sum;
  }
  report.converged = false;
  for (int sweep = 0; sweep < settings.max_sweeps; ++sweep) {
    double largest = 0.0;
    for (std::size_t i = 0; i < k; ++i) {
      const double* row = s + i * stride;
      const double diagonal = row[i];
      // A row that cannot yield or push (S_ii = 0) keeps lambda = 0.
      double updated = 0.0;
      if (diagonal > 0.0) updated = std::max(0.0, lambda[i] + residual[i] / diagonal);
      const double change = updated - lambda[i];
      if (change == 0.0) continue;
      lambda[i] = updated;
      for (std::size_t j = 0; j < k; ++j) residual[j] -= change * row[j];
      largest = std::max(largest, diagonal * std::abs(change));
    }
    ++report.sweeps;
    report.last_change_m = largest;
    if (largest <= settings.tolerance_m) {
      report.converged = true;
      break;
    }
  }
  return report;
}

}  // namespace fahr::contact
