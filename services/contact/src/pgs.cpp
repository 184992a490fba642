// Projected Gauss-Seidel sweeps in fixed row order.
#include "fahr/contact/pgs.h"

#include <algorithm>
#include <cmath>

namespace fahr::contact {

PgsReport solve_pgs(const double* s, std::size_t stride, std::size_t k, const double* b, double* lambda,
                    const PgsSettings& settings) {
  PgsReport report;
  if (k == 0) return report;
  report.converged = false;
  for (int sweep = 0; sweep < settings.max_sweeps; ++sweep) {
    double largest = 0.0;
    for (std::size_t i = 0; i < k; ++i) {
      const double* row = s + i * stride;
      const double diagonal = row[i];
      // A row that cannot yield or push (S_ii = 0) keeps lambda = 0.
      if (!(diagonal > 0.0)) {
        lambda[i] = 0.0;
        continue;
      }
      double residual = b[i];  // b_i - (S lambda)_i: the gap still to close, m
      for (std::size_t j = 0; j < k; ++j) residual -= row[j] * lambda[j];
      const double updated = std::max(0.0, lambda[i] + residual / diagonal);
      largest = std::max(largest, diagonal * std::abs(updated - lambda[i]));
      lambda[i] = updated;
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
