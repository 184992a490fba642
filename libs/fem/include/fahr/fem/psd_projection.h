// Projection of a symmetric 9x9 Hessian to positive semi-definite by a full
// eigen-decomposition: material-independent, for energies without an
// analytic eigensystem and as the reference the analytic ones are tested
// against.
#pragma once

#include "fahr/fem/hyperelastic_material.h"

namespace fahr::fem {

// `h` (symmetric; only its lower triangle is read) with its negative
// eigenvalues set to zero. Allocation-free (Eigen's fixed-size symmetric
// solver: Householder tridiagonalisation, then implicit QR).
Matrix9d project_to_psd(const Matrix9d& h);

}  // namespace fahr::fem
