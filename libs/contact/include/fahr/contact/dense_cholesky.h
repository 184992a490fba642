// In-place Cholesky factorisation and solve of a small dense symmetric
// positive definite matrix on caller-owned storage (no allocation), for the
// local stiffness of the active set.
#pragma once

#include <cstddef>

namespace fahr::contact {

// Factorises the leading n x n block of `a` (row stride `stride`) into its
// lower triangle L with A = L L^T. A pivot below `min_pivot` (the matrix is
// singular along some direction: redundant rigid rows) is replaced by it, so
// that direction gets a huge but finite stiffness instead of a NaN. Returns
// the number of pivots replaced.
int cholesky_in_place(double* a, std::size_t stride, std::size_t n, double min_pivot);

// Solves L L^T x = rhs in place of `rhs` with the factor from above.
void cholesky_solve(const double* factor, std::size_t stride, std::size_t n, double* rhs);

}  // namespace fahr::contact
