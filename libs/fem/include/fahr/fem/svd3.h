// A 3x3 singular value decomposition for the hyperelastic tangent, several
// times faster than Eigen's JacobiSVD on 3x3 (which sweeps two-sided Jacobi
// rotations with a general 2x2 SVD each).
//
// Method: the symmetric eigenproblem of C = F^T F by cyclic one-sided Jacobi
// rotations (a 3x3 converges to round-off in three or four sweeps) gives V
// and the squared singular values; U's first two columns are F v0 and F v1
// normalised (Gram-Schmidt against each other), the third their cross
// product, so U and V are proper rotations; the singular values are then
// read back as u_i . F v_i, which keeps the smallest one accurate (not the
// square root of a round-off-sized eigenvalue of C) and gives it the sign of
// det F: the rotation-variant SVD of Irving, Teran and Fedkiw (SCA 2004),
// F = U diag(s) V^T with s0 >= s1 >= |s2| and s2 < 0 for an inverted F.
// Degenerate F (rank 1 or 0) get any orthonormal completion.
#pragma once

#include <Eigen/Core>

namespace fahr::fem {

struct Svd3 {
  Eigen::Matrix3d u;  // proper rotation
  Eigen::Vector3d s;  // s0 >= s1 >= |s2|, s2 carries the sign of det F
  Eigen::Matrix3d v;  // proper rotation
};

// Allocation-free, defined for every finite F.
Svd3 rotation_variant_svd(const Eigen::Matrix3d& f);

// Eigenvalues (ascending) and orthonormal eigenvectors (columns, a proper
// rotation) of a symmetric 3x3 by cyclic Jacobi; only the upper triangle is
// read.
void symmetric_eigen3(const Eigen::Matrix3d& a, Eigen::Vector3d& values, Eigen::Matrix3d& vectors);

}  // namespace fahr::fem
