// Stable Neo-Hookean with a Yeoh term: energy, stress, Hessian and its
// analytic eigensystem (formulas and sources in stable_neo_hookean.h).
#include "fahr/fem/stable_neo_hookean.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cassert>
#include <cmath>

#include "fahr/fem/svd3.h"

namespace fahr::fem {
namespace {

struct Parameters {
  double mu = 0.0;
  double lambda = 0.0;
  double c20 = 0.0;
};

// Linearising at F = I + dF (I_C = 3, J = 1, D = 0; cof F changes by
// tr(dF) I - dF^T) gives the stress
//   2 Psi_I (dF + dF^T) + (4 Psi_II + 4 Psi_IJ + Psi_JJ - 2 Psi_I) tr(dF) I,
// using Psi_J = lambda (1 - alpha) = -2 Psi_I there (rest stability). The
// Yeoh term's share of 4 Psi_II + 4 Psi_IJ + Psi_JJ is 8 c20 - 16 c20 +
// 8 c20 = 0. Equal to 2 mu_LE eps + lambda_LE tr(eps) I when 2 Psi_I = mu_LE
// and lambda + 4 Psi_II(log) - 2 Psi_I = lambda_LE. With the log term
// 2 Psi_I = 3/4 mu and 4 Psi_II = mu/8: mu = 4/3 mu_LE, lambda = lambda_LE +
// 5/6 mu_LE; without it 2 Psi_I = mu and Psi_II = 0: mu = mu_LE, lambda =
// lambda_LE + mu_LE. lambda > 0 for every valid nu (> -1).
Parameters map_parameters(const Material& material, bool log_term) {
  const LameParameters lame = lame_parameters(material);
  Parameters p;
  p.c20 = material.yeoh_c20_over_c10 * lame.mu_pa / 2.0;
  if (log_term) {
    p.mu = 4.0 / 3.0 * lame.mu_pa;
    p.lambda = lame.lambda_pa + 5.0 / 6.0 * lame.mu_pa;
  } else {
    p.mu = lame.mu_pa;
    p.lambda = lame.lambda_pa + lame.mu_pa;
  }
  return p;
}

// [a]x, the matrix of b -> a x b.
Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& a) {
  Eigen::Matrix3d m;
  m << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return m;
}

// cof F = det(F) F^-T, column by column from F's columns f0, f1, f2 (defined
// for singular F too): dJ/dF.
Eigen::Matrix3d cofactor(const Eigen::Matrix3d& f) {
  Eigen::Matrix3d c;
  c.col(0) = f.col(1).cross(f.col(2));
  c.col(1) = f.col(2).cross(f.col(0));
  c.col(2) = f.col(0).cross(f.col(1));
  return c;
}

// Twists and flips in the plane (a, b) of each singular pair, k the third
// index; only H_J separates them, by -+ s_k.
constexpr int kPairs[3][3] = {{1, 2, 0}, {0, 2, 1}, {0, 1, 2}};

}  // namespace

StableNeoHookean::StableNeoHookean(const Material& material, StableNeoHookeanOptions options) {
  assert(validate(material)[0] == '\0');
  const Parameters p = map_parameters(material, options.log_term);
  mu_ = p.mu;
  lambda_ = p.lambda;
  c20_ = p.c20;
  log_term_ = options.log_term;
  // P(I) = (2 Psi_I + lambda (1 - alpha)) I = 0, with 2 Psi_I = mu - mu/4 or
  // mu (the Yeoh term's D = 0 at rest).
  alpha_ = 1.0 + (log_term_ ? 0.75 : 1.0) * mu_ / lambda_;
  rest_volume_energy_ = 0.5 * lambda_ * (1.0 - alpha_) * (1.0 - alpha_);
}

StableNeoHookean::Partials StableNeoHookean::partials(double i_c, double j) const {
  // Psi = mu/2 (I - 3) - [mu/2 log(I + 1)] + lambda/2 (J - alpha)^2 + c20 D^2,
  // D = I - 2 J - 1. I >= 0, so I + 1 >= 1.
  const double d = i_c - 2.0 * j - 1.0;
  const double log_i = log_term_ ? 0.5 * mu_ / (i_c + 1.0) : 0.0;
  const double log_ii = log_term_ ? 0.5 * mu_ / ((i_c + 1.0) * (i_c + 1.0)) : 0.0;
  Partials p;
  p.i = 0.5 * mu_ - log_i + 2.0 * c20_ * d;
  p.j = lambda_ * (j - alpha_) - 4.0 * c20_ * d;
  p.ii = log_ii + 2.0 * c20_;
  p.ij = -4.0 * c20_;
  p.jj = lambda_ + 8.0 * c20_;
  return p;
}

double StableNeoHookean::energy_density(const Eigen::Matrix3d& f) const {
  const double i_c = f.squaredNorm();
  const double j = f.determinant();
  const double d = i_c - 2.0 * j - 1.0;
  // log((I_C + 1) / 4) rather than log(I_C + 1): a constant, so that Psi(I) = 0.
  const double log_part = log_term_ ? 0.5 * mu_ * std::log((i_c + 1.0) / 4.0) : 0.0;
  const double shear = 0.5 * mu_ * (i_c - 3.0) - log_part;
  const double volume = 0.5 * lambda_ * (j - alpha_) * (j - alpha_) - rest_volume_energy_;
  return shear + volume + c20_ * d * d;
}

Eigen::Matrix3d StableNeoHookean::first_piola(const Eigen::Matrix3d& f) const {
  const Partials p = partials(f.squaredNorm(), f.determinant());
  return 2.0 * p.i * f + p.j * cofactor(f);
}

Matrix9d StableNeoHookean::hessian(const Eigen::Matrix3d& f) const {
  const Partials p = partials(f.squaredNorm(), f.determinant());
  const Vector9d vec_f = vec(f);
  const Vector9d g = vec(cofactor(f));
  Matrix9d h = 4.0 * p.ii * vec_f * vec_f.transpose() + p.jj * g * g.transpose();
  const Matrix9d coupling = vec_f * g.transpose();
  h += 2.0 * p.ij * (coupling + coupling.transpose());
  h.diagonal().array() += 2.0 * p.i;
  // Psi_J H_J: J = f0 . (f1 x f2) is linear in each column, so H_J's
  // diagonal blocks vanish and block (a, b) is d(dJ/df_a)/df_b, e.g.
  // d(f1 x f2)/df2 = [f1]x.
  const Eigen::Matrix3d x0 = p.j * cross_matrix(f.col(0));
  const Eigen::Matrix3d x1 = p.j * cross_matrix(f.col(1));
  const Eigen::Matrix3d x2 = p.j * cross_matrix(f.col(2));
  h.block<3, 3>(0, 3) -= x2;
  h.block<3, 3>(0, 6) += x1;
  h.block<3, 3>(3, 0) += x2;
  h.block<3, 3>(3, 6) -= x0;
  h.block<3, 3>(6, 0) -= x1;
  h.block<3, 3>(6, 3) += x0;
  return h;
}

Eigen::Matrix3d StableNeoHookean::scaling_hessian(const Eigen::Vector3d& s) const {
  // Psi(s0, s1, s2) through I = |s|^2 and J = s0 s1 s2: with c = dJ/ds =
  // (s1 s2, s0 s2, s0 s1) and d2J/ds2 = [[0, s2, s1], [s2, 0, s0], [s1, s0, 0]],
  // 2 Psi_I I + 4 Psi_II s s^T + 2 Psi_IJ (s c^T + c s^T) + Psi_JJ c c^T
  // + Psi_J d2J/ds2.
  const Partials p = partials(s.squaredNorm(), s.prod());
  const Eigen::Vector3d c(s(1) * s(2), s(0) * s(2), s(0) * s(1));
  const Eigen::Matrix3d coupling = s * c.transpose();
  Eigen::Matrix3d a = 4.0 * p.ii * s * s.transpose() + p.jj * c * c.transpose() +
                      2.0 * p.ij * (coupling + coupling.transpose());
  a.diagonal().array() += 2.0 * p.i;
  a(0, 1) += p.j * s(2);
  a(0, 2) += p.j * s(1);
  a(1, 2) += p.j * s(0);
  a(1, 0) = a(0, 1);
  a(2, 0) = a(0, 2);
  a(2, 1) = a(1, 2);
  return a;
}

HessianEigensystem StableNeoHookean::hessian_eigensystem(const Eigen::Matrix3d& f) const {
  const Svd3 svd = rotation_variant_svd(f);
  const Partials partial = partials(svd.s.squaredNorm(), svd.s.prod());
  Eigen::Vector3d scaling_values;
  Eigen::Matrix3d scaling_vectors;
  symmetric_eigen3(scaling_hessian(svd.s), scaling_values, scaling_vectors);
  HessianEigensystem out;
  for (int m = 0; m < 3; ++m) {
    out.values(m) = scaling_values(m);
    out.vectors.col(m) = vec(svd.u * scaling_vectors.col(m).asDiagonal() * svd.v.transpose());
  }
  const double half_sqrt2 = std::sqrt(0.5);
  for (int p = 0; p < 3; ++p) {
    const Eigen::Matrix3d ab = svd.u.col(kPairs[p][0]) * svd.v.col(kPairs[p][1]).transpose();
    const Eigen::Matrix3d ba = svd.u.col(kPairs[p][1]) * svd.v.col(kPairs[p][0]).transpose();
    const double s_k = svd.s(kPairs[p][2]);
    out.values(3 + 2 * p) = 2.0 * partial.i + partial.j * s_k;
    out.vectors.col(3 + 2 * p) = half_sqrt2 * vec(ab - ba);
    out.values(4 + 2 * p) = 2.0 * partial.i - partial.j * s_k;
    out.vectors.col(4 + 2 * p) = half_sqrt2 * vec(ab + ba);
  }
  return out;
}

Matrix9d StableNeoHookean::projected_hessian(const Eigen::Matrix3d& f) const {
  // H minus its negative modes, sum over lambda_m < 0 of lambda_m q_m q_m^T:
  // the same matrix as rebuilding from the clamped eigensystem, but only the
  // modes that are negative are formed, and usually few are (twists of a
  // compressed element; scaling modes only in strong compression).
  Matrix9d h = hessian(f);
  const Svd3 svd = rotation_variant_svd(f);
  const Partials partial = partials(svd.s.squaredNorm(), svd.s.prod());
  const double half_sqrt2 = std::sqrt(0.5);
  for (int p = 0; p < 3; ++p) {
    const double s_k = svd.s(kPairs[p][2]);
    for (const double sign : {-1.0, 1.0}) {  // twist, flip
      const double value = 2.0 * partial.i - sign * partial.j * s_k;
      if (value >= 0.0) continue;
      const Eigen::Matrix3d ab = svd.u.col(kPairs[p][0]) * svd.v.col(kPairs[p][1]).transpose();
      const Eigen::Matrix3d ba = svd.u.col(kPairs[p][1]) * svd.v.col(kPairs[p][0]).transpose();
      const Vector9d q = half_sqrt2 * vec(ab + sign * ba);
      h.noalias() -= value * q * q.transpose();
    }
  }
  const Eigen::Matrix3d a = scaling_hessian(svd.s);
  // Positive definite by its leading minors: then no scaling mode is
  // negative and the 3x3 eigen-solve is skipped.
  const bool definite =
      a(0, 0) > 0.0 && a(0, 0) * a(1, 1) - a(0, 1) * a(0, 1) > 0.0 && a.determinant() > 0.0;
  if (!definite) {
    Eigen::Vector3d values;
    Eigen::Matrix3d vectors;
    symmetric_eigen3(a, values, vectors);
    for (int m = 0; m < 3; ++m) {
      const double value = values(m);
      if (value >= 0.0) continue;
      const Vector9d q = vec(svd.u * vectors.col(m).asDiagonal() * svd.v.transpose());
      h.noalias() -= value * q * q.transpose();
    }
  }
  return h;
}

}  // namespace fahr::fem
