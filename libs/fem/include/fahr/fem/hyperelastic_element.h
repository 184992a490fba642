// Element level of a hyperelastic material on a linear tetrahedron: the
// derivative of the deformation gradient by the node positions, the nodal
// forces and the 12x12 stiffness. Material-independent: F comes from
// geometry::deformation_gradient (with ElementRest's Dm^-1), P and H from any
// HyperelasticMaterial (hyperelastic_material.h) at that F, the volume from
// ElementRest. Everything here is fixed-size and allocation-free.
//
// Node order and DOF order: the tet's nodes 0..3 as in ElementRest::tets;
// 12-vectors are (x0, y0, z0, x1, ..., z3), node a's three at 3a.
#pragma once

#include <Eigen/Core>

#include "fahr/fem/hyperelastic_material.h"

namespace fahr::fem {

using Vector12d = Eigen::Matrix<double, 12, 1>;
using Matrix12d = Eigen::Matrix<double, 12, 12>;
using Matrix9x12d = Eigen::Matrix<double, 9, 12>;
// dvec(F)/dx, 9x12, 1/m: F is linear in x, F = sum_a x_a g_a^T with g_a the
// rest gradient of node a's shape function (shape_gradients(dm_inv),
// element_rest.h), so entry (i + 3 j, 3 a + i) is g_a[j] and every other
// entry is 0. Constant per element: compute once at set-up or per use.
Matrix9x12d deformation_gradient_jacobian(const Eigen::Matrix3d& dm_inv);

// Elastic nodal forces f = -d(V Psi)/dx = -V (dF/dx)^T vec(P), N, for the
// stress P (Pa) at this element's F and its rest volume V (m^3). They sum to
// zero.
Vector12d nodal_forces(const Matrix9x12d& df_dx, double volume_m3, const Eigen::Matrix3d& p);

// K = V (dF/dx)^T H (dF/dx), N/m: -df/dx for the exact Hessian H (Pa),
// symmetric (H must be: K's lower blocks are copied from its upper ones);
// positive semi-definite when H is (a projected Hessian). `df_dx` must be
// deformation_gradient_jacobian()'s: its block structure is used.
Matrix12d element_stiffness(const Matrix9x12d& df_dx, double volume_m3, const Matrix9d& h);
// The same K from the element's shape gradients (shape_gradients(dm_inv),
// element_rest.h: column a is g_a), which is all of dF/dx: what a body
// assembling every element uses, without forming the 9x12 matrix.
Matrix12d element_stiffness(const Eigen::Matrix<double, 3, 4>& g, double volume_m3,
                            const Matrix9d& h);

}  // namespace fahr::fem
