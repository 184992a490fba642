// Stable Neo-Hookean tissue with the tongue's compression stiffening: one
// hyperelastic energy, its exact stress, Hessian and analytic eigensystem,
// defined and smooth for every F, flat and inverted elements included.
//
// Source of the base energy: Smith, de Goes and Kim, "Stable Neo-Hookean
// Flesh Simulation", ACM Trans. Graph. 37(2), article 12, 2018. With
// I_C = tr(F^T F) = |F|^2 and J = det F, their energy is
//   mu/2 (I_C - 3) - mu/2 log(I_C + 1) + lambda/2 (J - alpha)^2,
// the log term optional (it keeps the rest state stable for any lambda and
// gives the energy its slight stiffening in tension). alpha moves the volume
// term's minimum so that F = I carries no stress: 1 + 3 mu / (4 lambda) with
// the log term, 1 + mu / lambda without. No J^(-2/3) and no log J, so the
// energy stays finite as J -> 0 and smooth through J < 0: an inverted element
// feels a finite force back towards J > 0 instead of a wall it is already
// on the wrong side of.
//
// Compression stiffening: Gerard et al.'s Yeoh fit of tongue tissue
// (material.h, material.cpp: C20 / C10 = 0.47) as a second term in the same
// invariant, c20 (I_C - 3)^2 with c20 = (C20 / C10) mu_LE / 2 (the small-strain
// Yeoh shear modulus is 2 C10 = mu_LE). It stiffens uniaxial and shear
// deformation like the Yeoh solid; I_C is used rather than the isochoric
// I1bar = J^(-2/3) I_C of compression_stiffening.h because I1bar is singular
// at J = 0 and would bring back the barrier SNH removes. The price: at rest
// its Hessian, 8 c20 vec(I) vec(I)^T, adds 8 c20 to the small-strain lambda;
// the mapping below takes it off again.
//
// Small-strain match: lambda and mu are chosen so that the linearisation at
// F = I is linear elasticity with the material's E and nu (mu_LE, lambda_LE
// of lame_parameters()). With the log term this is the paper's
// reparametrisation, mu = 4/3 mu_LE, lambda = lambda_LE + 5/6 mu_LE; without
// it mu = mu_LE, lambda = lambda_LE + mu_LE; either way minus 8 c20. Derived
// in stable_neo_hookean.cpp; the tests check the stress against linear
// elasticity at F = I + eps G.
//
// Derivatives, with kappa = 2 dPsi/dI_C and beta = 4 d2Psi/dI_C^2 (the
// paper's gradient and Hessian, plus the Yeoh term's share of kappa, beta):
//   P = kappa F + lambda (J - alpha) cof F
//   H = kappa I_9 + beta vec F vec F^T + lambda g g^T + lambda (J - alpha) H_J
// with g = vec(cof F) = dJ/dvec F and H_J = d2J/dvec F^2. Its eigensystem
// (the paper's analysis, here with the Yeoh term in kappa and beta): with
// F = U S V^T, U and V rotations and S = diag(s0, s1, s2) (s2 < 0 when
// inverted), for each pair (i, j) with third index k a twist
// U (e_i e_j^T - e_j e_i^T) V^T / sqrt 2 of eigenvalue kappa + lambda (J -
// alpha) s_k and a flip (+ instead of -) of kappa - lambda (J - alpha) s_k;
// and three scaling modes U diag(w) V^T, w the eigenvectors of the 3x3 Hessian
// of Psi in (s0, s1, s2). Projection clamps these nine at zero.
#pragma once

#include <Eigen/Core>

#include "fahr/fem/hyperelastic_material.h"
#include "fahr/fem/material.h"

namespace fahr::fem {

struct StableNeoHookeanOptions {
  // The paper's -mu/2 log(I_C + 1) term; false: the plain quadratic form.
  bool log_term = true;
};

// Eigenvalues (Pa) and orthonormal eigenvectors (columns, vec of 3x3
// eigen-matrices) of the 9x9 Hessian: H = vectors diag(values) vectors^T.
struct HessianEigensystem {
  Vector9d values;
  Matrix9d vectors;
};

class StableNeoHookean {
 public:
  // From the material's E (Pa), nu and Yeoh ratio C20/C10 (its density and
  // damping are not used here). Asserts what validate_stable_neo_hookean()
  // checks: call that first on input from outside.
  explicit StableNeoHookean(const Material& material, StableNeoHookeanOptions options = {});

  double mu_pa() const { return mu_; }          // SNH mu, Pa (4/3 mu_LE with the log term)
  double lambda_pa() const { return lambda_; }  // SNH lambda, Pa, > 0
  double alpha() const { return alpha_; }       // rest-stability shift of J, dimensionless
  double yeoh_c20_pa() const { return c20_; }   // c20 of c20 (I_C - 3)^2, Pa, >= 0
  bool log_term() const { return log_term_; }

  // Psi, Pa; 0 at F = I and at every rotation.
  double energy_density(const Eigen::Matrix3d& f) const;
  // P = dPsi/dF, Pa.
  Eigen::Matrix3d first_piola(const Eigen::Matrix3d& f) const;
  // d2Psi/dvec(F)^2, Pa; indefinite in general (inverted, compressed).
  Matrix9d hessian(const Eigen::Matrix3d& f) const;
  // The analytic eigensystem of hessian(f), from one 3x3 SVD and one 3x3
  // symmetric eigen-solve.
  HessianEigensystem hessian_eigensystem(const Eigen::Matrix3d& f) const;
  // hessian(f) with its negative eigenvalues set to zero: hessian(f) minus
  // its negative modes, from the analytic eigensystem.
  Matrix9d projected_hessian(const Eigen::Matrix3d& f) const;

 private:
  // kappa = 2 dPsi/dI_C and beta = 4 d2Psi/dI_C^2 at I_C.
  double kappa(double i_c) const;
  double beta(double i_c) const;
  // The 3x3 Hessian of Psi in the signed singular values s.
  Eigen::Matrix3d scaling_hessian(const Eigen::Vector3d& s) const;

  double mu_ = 0.0;
  double lambda_ = 0.0;
  double alpha_ = 1.0;
  double c20_ = 0.0;
  double rest_volume_energy_ = 0.0;  // lambda/2 (1 - alpha)^2, taken off so Psi(I) = 0
  bool log_term_ = true;
};

static_assert(HyperelasticMaterial<StableNeoHookean>);

// Empty when `material` maps to a valid energy, otherwise a sentence naming
// the field: validate(material) and, because the Yeoh term's share of the
// small-strain lambda is taken off, a positive SNH lambda (with C20/C10 = 0.47
// this needs nu > 0.256 with the log term, nu > 0.234 without).
const char* validate_stable_neo_hookean(const Material& material,
                                        StableNeoHookeanOptions options = {});

}  // namespace fahr::fem
