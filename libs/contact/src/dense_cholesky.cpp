// Cholesky-Banachiewicz on the lower triangle, row-major, in place.
#include "fahr/contact/dense_cholesky.h"

#include <Eigen/Core>
#include <cmath>

namespace fahr::contact {

int cholesky_in_place(double* a, std::size_t stride, std::size_t n, double min_pivot) {
  int dropped = 0;
  for (std::size_t i = 0; i < n; ++i) {
    double* row = a + i * stride;
    for (std::size_t j = 0; j < i; ++j) {
      const double pivot = a[j * stride + j];
      if (pivot == 0.0) {
        row[j] = 0.0;  // row j was dropped: it takes no part
        continue;
      }
      double sum = row[j];
      for (std::size_t m = 0; m < j; ++m) sum -= row[m] * a[j * stride + m];
      row[j] = sum / pivot;
    }
    double sum = row[i];
    for (std::size_t m = 0; m < i; ++m) sum -= row[m] * row[m];
    if (sum > min_pivot) {
      row[i] = std::sqrt(sum);
      continue;
    }
    // Row i depends on the rows before it (or, with rounding, makes the
    // matrix slightly indefinite there): it is dropped, not propped up. A
    // floored pivot turned the next rows' multipliers into sum / 1e-6 and
    // grew them past the double range within a 64-row set (NaN stiffness).
    for (std::size_t m = 0; m <= i; ++m) row[m] = 0.0;
    ++dropped;
  }
  return dropped;
}

bool semidefinite(const double* a, std::size_t stride, std::size_t n, double diagonal_scale,
                  double tolerance, double* scratch) {
  // The dot products through Eigen (vectorised, several partial sums): this
  // runs every haptic tick on up to 80 rows, and only the pivots' signs
  // matter.
  using Row = Eigen::Map<const Eigen::VectorXd>;
  for (std::size_t i = 0; i < n; ++i) {
    const double* source = a + i * stride;
    double* row = scratch + i * stride;
    for (std::size_t j = 0; j < i; ++j) {
      const double pivot = scratch[j * stride + j];
      if (pivot == 0.0) {
        row[j] = 0.0;
        continue;
      }
      const auto m = static_cast<Eigen::Index>(j);
      row[j] = (source[j] - Row(row, m).dot(Row(scratch + j * stride, m))) / pivot;
    }
    const double diagonal = diagonal_scale * source[i];
    const double sum = diagonal - Row(row, static_cast<Eigen::Index>(i)).squaredNorm();
    if (sum > tolerance * diagonal) {
      row[i] = std::sqrt(sum);
      continue;
    }
    if (sum < -tolerance * diagonal) return false;
    for (std::size_t m = 0; m <= i; ++m) row[m] = 0.0;
  }
  return true;
}

void cholesky_solve(const double* factor, std::size_t stride, std::size_t n, double* rhs) {
  for (std::size_t i = 0; i < n; ++i) {  // L y = rhs
    const double pivot = factor[i * stride + i];
    if (pivot == 0.0) {
      rhs[i] = 0.0;
      continue;
    }
    double sum = rhs[i];
    for (std::size_t m = 0; m < i; ++m) sum -= factor[i * stride + m] * rhs[m];
    rhs[i] = sum / pivot;
  }
  for (std::size_t i = n; i-- > 0;) {  // L^T x = y
    const double pivot = factor[i * stride + i];
    if (pivot == 0.0) {
      rhs[i] = 0.0;
      continue;
    }
    double sum = rhs[i];
    for (std::size_t m = i + 1; m < n; ++m) sum -= factor[m * stride + i] * rhs[m];
    rhs[i] = sum / pivot;
  }
}

}  // namespace fahr::contact
