// Stable Neo-Hookean tissue with the tongue's compression stiffening: one
// hyperelastic energy, its exact stress, Hessian and analytic eigensystem,
// defined and smooth for every F, flat and inverted elements included.
//
// Base energy: Smith, de Goes and Kim, "Stable Neo-Hookean Flesh
// Simulation", ACM Trans. Graph. 37(2), article 12, 2018. With
// I_C = tr(F^T F) = |F|^2 and J = det F, their energy is
//   mu/2 (I_C - 3) - mu/2 log(I_C + 1) + lambda/2 (J - alpha)^2,
// the log term optional (it keeps the rest state stable for any lambda).
// alpha moves the volume term's minimum so that F = I carries no stress:
// 1 + 3 mu / (4 lambda) with the log term, 1 + mu / lambda without. No
// J^(-2/3) and no log J, so the energy stays finite as J -> 0 and smooth
// through J < 0: an inverted element feels a finite force back towards
// J > 0 instead of a wall it is already on the wrong side of.
// Small-strain match, the paper's reparametrisation: mu = 4/3 mu_LE and
// lambda = lambda_LE + 5/6 mu_LE with the log term, mu = mu_LE and lambda =
// lambda_LE + mu_LE without, mu_LE and lambda_LE from E and nu
// (lame_parameters()); derived again in stable_neo_hookean.cpp and checked by
// the tests against linear elasticity at F = I + eps G.
//
// Compression stiffening: Gerard et al.'s Yeoh fit of tongue tissue,
// W = C10 (I1 - 3) + C20 (I1 - 3)^2 with C20 / C10 = 0.47 (material.h,
// material.cpp), fitted as incompressible and, in compressible form, written
// with the isochoric I1bar = J^(-2/3) I_C. Added here as c20 D^2 with
// c20 = (C20 / C10) mu_LE / 2 (the small-strain Yeoh shear modulus 2 C10 is
// mu_LE) and
//   D = (I_C - 3) - 2 (J - 1) = I_C - 2 J - 1,
// which equals I1bar - 3 to first order in J - 1 (exactly when J = 1), yet is
// a polynomial in F, smooth through J = 0. The alternatives:
// - I1bar - 3 itself (compression_stiffening.h): singular at J = 0, it would
//   bring back the barrier that SNH removes.
// - I_C - 3: counts lost volume as negative distortion, so a compressed
//   element that gives up volume loses its stiffening (at 50 % uniaxial
//   compression of the tongue material, J = 0.81: D = 0.87, I1bar - 3 =
//   1.01, I_C - 3 = 0.48; hyperelastic_element_test prints them); and its
//   square adds 8 c20 to the small-strain lambda, which the mapping would
//   have to take back (lambda <= 0 below nu = 0.26 at the tongue's ratio).
// dD/dF = 2 (F - cof F) vanishes at F = I, so the term leaves the
// small-strain stress, the rest state and the mapping above untouched.
// Confined compression F = diag(1, 1, s) gives D = (1 - s)^2: the term
// stiffens it too, and keeps growing past s = 0.
//
// Derivatives: Psi is a function of the invariants I = I_C and J. With
// f = vec F, g = vec(cof F) = dJ/dvec F, H_J = d2J/dvec F^2 and Psi_I,
// Psi_J, ... its partial derivatives,
//   P = 2 Psi_I F + Psi_J cof F
//   H = 2 Psi_I I_9 + 4 Psi_II f f^T + 2 Psi_IJ (f g^T + g f^T)
//       + Psi_JJ g g^T + Psi_J H_J,
// the paper's gradient and Hessian for Psi_IJ = 0 and the Yeoh term's
// coupling otherwise. Eigensystem (the paper's analysis; f and g lie in the
// scaling subspace, so the coupling stays there): with F = U S V^T, U and V
// rotations and S = diag(s0, s1, s2) (s2 < 0 when inverted), for each pair
// (i, j) with third index k a twist U (e_i e_j^T - e_j e_i^T) V^T / sqrt 2 of
// eigenvalue 2 Psi_I + Psi_J s_k and a flip (+ instead of -) of
// 2 Psi_I - Psi_J s_k; and three scaling modes U diag(w) V^T, w the
// eigenvectors of the 3x3 Hessian of Psi in (s0, s1, s2). The projection
// clamps these nine at zero.
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
  // From the material's E (Pa), nu and Yeoh ratio C20/C10; its density and
  // damping are not used here. Asserts that validate(material) is empty:
  // check input from outside with it first.
  explicit StableNeoHookean(const Material& material, StableNeoHookeanOptions options = {});

  double mu_pa() const { return mu_; }          // SNH mu, Pa (4/3 mu_LE with the log term)
  double lambda_pa() const { return lambda_; }  // SNH lambda, Pa, > 0
  double alpha() const { return alpha_; }       // rest-stability shift of J, dimensionless
  double yeoh_c20_pa() const { return c20_; }   // c20 of c20 (I_C - 2 J - 1)^2, Pa, >= 0
  bool log_term() const { return log_term_; }

  // Psi, Pa; 0 at F = I and at every rotation.
  double energy_density(const Eigen::Matrix3d& f) const;
  // P = dPsi/dF, Pa.
  Eigen::Matrix3d first_piola(const Eigen::Matrix3d& f) const;
  // d2Psi/dvec(F)^2, Pa; indefinite in general (inverted, compressed).
  Matrix9d hessian(const Eigen::Matrix3d& f) const;
  // The analytic eigensystem of hessian(f), from one 3x3 SVD (svd3.h) and one 3x3
  // symmetric eigen-solve.
  HessianEigensystem hessian_eigensystem(const Eigen::Matrix3d& f) const;
  // hessian(f) with its negative eigenvalues set to zero: hessian(f) minus
  // its negative modes, from the analytic eigensystem.
  Matrix9d projected_hessian(const Eigen::Matrix3d& f) const;

 private:
  // First and second partial derivatives of Psi in I = I_C and J, Pa.
  struct Partials {
    double i = 0.0, j = 0.0, ii = 0.0, ij = 0.0, jj = 0.0;
  };
  Partials partials(double i_c, double j) const;
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

}  // namespace fahr::fem
