// In-place Cholesky factorisation and solve of a small dense symmetric
// positive definite matrix on caller-owned storage (no allocation), for the
// local stiffness of the active set.
#pragma once

#include <cstddef>

namespace fahr::contact {

// Factorises the leading n x n block of `a` (row stride `stride`) into its
// lower triangle L with A = L L^T, for a symmetric positive semidefinite A.
// A row whose pivot is not above `min_pivot` depends on the rows before it
// (redundant rows: neighbouring spheres under one blade face) and is
// dropped: its row and column of L are zero, and the solve below gives it
// x = 0, so a consistent system is solved on the independent rows. Returns
// the number of rows dropped.
int cholesky_in_place(double* a, std::size_t stride, std::size_t n, double min_pivot);

// Whether the leading n x n block of `a` (row stride `stride`), with its
// diagonal scaled by diagonal_scale, is positive semidefinite to a relative
// tolerance: factorised as above into `scratch` (same layout), a pivot
// below -tolerance * a_ii says it is not. Pivots within the tolerance of
// zero are rows depending on the rows before them (dropped, as above);
// rows with a_ii = 0 take no part. Stops at the first negative pivot.
bool semidefinite(const double* a, std::size_t stride, std::size_t n, double diagonal_scale,
                  double tolerance, double* scratch);

// Solves L L^T x = rhs in place of `rhs` with the factor from above (x = 0
// on dropped rows).
void cholesky_solve(const double* factor, std::size_t stride, std::size_t n, double* rhs);

}  // namespace fahr::contact
