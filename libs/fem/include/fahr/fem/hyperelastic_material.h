// The shape of a hyperelastic material: an energy density of the deformation
// gradient with its exact first and second derivatives, so that an implicit
// step can take the force and its consistent tangent from one function.
//
// Conventions shared by every material and by hyperelastic_element.h:
// - F is the deformation gradient, rest to current, dimensionless 3x3; any
//   F is accepted, flat (det F = 0) and inverted (det F < 0) included.
// - Psi(F) is energy per rest volume, J/m^3 = Pa; P = dPsi/dF is the first
//   Piola-Kirchhoff stress, Pa (force per rest area).
// - Second derivatives are 9x9 on vec(F), column-major like Eigen's storage:
//   vec(F)[i + 3 j] = F(i, j), i.e. the three columns of F stacked. The
//   Hessian H = d2Psi/dvec(F)^2, Pa, is symmetric.
// - The projected Hessian is H with its negative eigenvalues set to zero: the
//   nearest positive semi-definite matrix in the Frobenius norm, what a
//   Newton step needs so that its system stays positive definite.
#pragma once

#include <Eigen/Core>
#include <concepts>

namespace fahr::fem {

using Vector9d = Eigen::Matrix<double, 9, 1>;
using Matrix9d = Eigen::Matrix<double, 9, 9>;

// vec(F) as a 9-vector (column-major) and back.
inline Vector9d vec(const Eigen::Matrix3d& f) {
  return Eigen::Map<const Vector9d>(f.data());
}
inline Eigen::Matrix3d unvec(const Vector9d& v) {
  return Eigen::Map<const Eigen::Matrix3d>(v.data());
}

// Every evaluation is a const member, allocation-free and thread-safe, and
// defined for every finite F.
template <class M>
concept HyperelasticMaterial = requires(const M& material, const Eigen::Matrix3d& f) {
  { material.energy_density(f) } -> std::convertible_to<double>;
  { material.first_piola(f) } -> std::convertible_to<Eigen::Matrix3d>;
  { material.hessian(f) } -> std::convertible_to<Matrix9d>;
  { material.projected_hessian(f) } -> std::convertible_to<Matrix9d>;
};

}  // namespace fahr::fem
