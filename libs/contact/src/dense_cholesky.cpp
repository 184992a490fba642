// Cholesky-Banachiewicz on the lower triangle, row-major, in place.
#include "fahr/contact/dense_cholesky.h"

#include <cmath>

namespace fahr::contact {

int cholesky_in_place(double* a, std::size_t stride, std::size_t n, double min_pivot) {
  int replaced = 0;
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j <= i; ++j) {
      double sum = a[i * stride + j];
      for (std::size_t m = 0; m < j; ++m) sum -= a[i * stride + m] * a[j * stride + m];
      if (i == j) {
        if (!(sum > min_pivot)) {
          sum = min_pivot;
          ++replaced;
        }
        a[i * stride + i] = std::sqrt(sum);
      } else {
        a[i * stride + j] = sum / a[j * stride + j];
      }
    }
  }
  return replaced;
}

void cholesky_solve(const double* factor, std::size_t stride, std::size_t n, double* rhs) {
  for (std::size_t i = 0; i < n; ++i) {  // L y = rhs
    double sum = rhs[i];
    for (std::size_t m = 0; m < i; ++m) sum -= factor[i * stride + m] * rhs[m];
    rhs[i] = sum / factor[i * stride + i];
  }
  for (std::size_t i = n; i-- > 0;) {  // L^T x = y
    double sum = rhs[i];
    for (std::size_t m = i + 1; m < n; ++m) sum -= factor[m * stride + i] * rhs[m];
    rhs[i] = sum / factor[i * stride + i];
  }
}

}  // namespace fahr::contact
