// Stable Neo-Hookean with a Yeoh term in I_C: energy, stress, Hessian and its
// analytic eigensystem (formulas and sources in stable_neo_hookean.h).
#include "fahr/fem/stable_neo_hookean.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cassert>
#include <cmath>

namespace fahr::fem {
namespace {

struct Parameters {
  double mu = 0.0;
  double lambda = 0.0;
  double c20 = 0.0;
};

// Linearising at F = I + dF (cof F changes by tr(dF) I - dF^T there, and
// I_C = 3, J = 1) gives the stress
//   kappa(3) (dF + dF^T) + (lambda + beta(3) - kappa(3)) tr(dF) I,
// using lambda (1 - alpha) = -kappa(3), the rest-stability condition. Equal
// to 2 mu_LE eps + lambda_LE tr(eps) I when kappa(3) = mu_LE and
// lambda = lambda_LE + kappa(3) - beta(3). With the log term kappa(3) =
// 3/4 mu and beta(3) = mu/8 + 8 c20, so mu = 4/3 mu_LE and lambda =
// lambda_LE + 5/6 mu_LE - 8 c20 (the paper's mapping for c20 = 0); without,
// kappa(3) = mu and beta(3) = 8 c20.
Parameters map_parameters(const Material& material, bool log_term) {
  const LameParameters lame = lame_parameters(material);
  Parameters p;
  p.c20 = material.yeoh_c20_over_c10 * lame.mu_pa / 2.0;
  if (log_term) {
    p.mu = 4.0 / 3.0 * lame.mu_pa;
    p.lambda = lame.lambda_pa + 5.0 / 6.0 * lame.mu_pa - 8.0 * p.c20;
  } else {
    p.mu = lame.mu_pa;
    p.lambda = lame.lambda_pa + lame.mu_pa - 8.0 * p.c20;
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

struct RotationVariantSvd {
  Eigen::Matrix3d u;
  Eigen::Matrix3d v;
  Eigen::Vector3d s;
};

RotationVariantSvd rotation_variant_svd(const Eigen::Matrix3d& f) {
  // U and V proper rotations, the sign of J carried by the smallest singular
  // value (Eigen sorts them in decreasing order): Irving, Teran and Fedkiw's
  // sign fix, as in corotation.cpp.
  const Eigen::JacobiSVD<Eigen::Matrix3d, Eigen::NoQRPreconditioner> svd(
      f, Eigen::ComputeFullU | Eigen::ComputeFullV);
  RotationVariantSvd out{svd.matrixU(), svd.matrixV(), svd.singularValues()};
  if (out.u.determinant() < 0.0) {
    out.u.col(2) = -out.u.col(2);
    out.s(2) = -out.s(2);
  }
  if (out.v.determinant() < 0.0) {
    out.v.col(2) = -out.v.col(2);
    out.s(2) = -out.s(2);
  }
  return out;
}

// Twists and flips in the plane (a, b) of each singular pair, k the third
// index; only H_J separates them, by -+ s_k.
constexpr int kPairs[3][3] = {{1, 2, 0}, {0, 2, 1}, {0, 1, 2}};

}  // namespace

StableNeoHookean::StableNeoHookean(const Material& material, StableNeoHookeanOptions options) {
  assert(validate_stable_neo_hookean(material, options)[0] == '\0');
  const Parameters p = map_parameters(material, options.log_term);
  mu_ = p.mu;
  lambda_ = p.lambda;
  c20_ = p.c20;
  log_term_ = options.log_term;
  // P(I) = kappa(3) I + lambda (1 - alpha) I = 0.
  alpha_ = 1.0 + kappa(3.0) / lambda_;
  rest_volume_energy_ = 0.5 * lambda_ * (1.0 - alpha_) * (1.0 - alpha_);
}

double StableNeoHookean::kappa(double i_c) const {
  // 2 dPsi/dI_C: mu from mu/2 (I_C - 3), -mu / (I_C + 1) from the log term,
  // 4 c20 (I_C - 3) from the Yeoh term. I_C >= 0, so I_C + 1 >= 1.
  const double log_part = log_term_ ? mu_ / (i_c + 1.0) : 0.0;
  return mu_ - log_part + 4.0 * c20_ * (i_c - 3.0);
}

double StableNeoHookean::beta(double i_c) const {
  // 4 d2Psi/dI_C^2.
  const double log_part = log_term_ ? 2.0 * mu_ / ((i_c + 1.0) * (i_c + 1.0)) : 0.0;
  return log_part + 8.0 * c20_;
}

double StableNeoHookean::energy_density(const Eigen::Matrix3d& f) const {
  const double i_c = f.squaredNorm();
  const double j = f.determinant();
  // log((I_C + 1) / 4) rather than log(I_C + 1): a constant, so that Psi(I) = 0.
  const double log_part = log_term_ ? 0.5 * mu_ * std::log((i_c + 1.0) / 4.0) : 0.0;
  const double shear = 0.5 * mu_ * (i_c - 3.0) - log_part + c20_ * (i_c - 3.0) * (i_c - 3.0);
  const double volume = 0.5 * lambda_ * (j - alpha_) * (j - alpha_) - rest_volume_energy_;
  return shear + volume;
}

Eigen::Matrix3d StableNeoHookean::first_piola(const Eigen::Matrix3d& f) const {
  const double i_c = f.squaredNorm();
  const double j = f.determinant();
  return kappa(i_c) * f + lambda_ * (j - alpha_) * cofactor(f);
}

Matrix9d StableNeoHookean::hessian(const Eigen::Matrix3d& f) const {
  const double i_c = f.squaredNorm();
  const double j = f.determinant();
  const Vector9d vec_f = vec(f);
  const Vector9d g = vec(cofactor(f));
  Matrix9d h = beta(i_c) * vec_f * vec_f.transpose() + lambda_ * g * g.transpose();
  h.diagonal().array() += kappa(i_c);
  // H_J: J = f0 . (f1 x f2) is linear in each column, so its diagonal blocks
  // vanish and block (a, b) is d(dJ/df_a)/df_b, e.g. d(f1 x f2)/df2 = [f1]x.
  const double volume_slope = lambda_ * (j - alpha_);
  const Eigen::Matrix3d x0 = volume_slope * cross_matrix(f.col(0));
  const Eigen::Matrix3d x1 = volume_slope * cross_matrix(f.col(1));
  const Eigen::Matrix3d x2 = volume_slope * cross_matrix(f.col(2));
  h.block<3, 3>(0, 3) -= x2;
  h.block<3, 3>(0, 6) += x1;
  h.block<3, 3>(3, 0) += x2;
  h.block<3, 3>(3, 6) -= x0;
  h.block<3, 3>(6, 0) -= x1;
  h.block<3, 3>(6, 3) += x0;
  return h;
}

Eigen::Matrix3d StableNeoHookean::scaling_hessian(const Eigen::Vector3d& s) const {
  // The Hessian of Psi(s0, s1, s2) = a(I_C) + b(J) in the singular values:
  // kappa I + beta s s^T + lambda c c^T + lambda (J - alpha) d2J/ds2 with
  // c = dJ/ds = (s1 s2, s0 s2, s0 s1).
  const double i_c = s.squaredNorm();
  const double volume_slope = lambda_ * (s.prod() - alpha_);
  const Eigen::Vector3d c(s(1) * s(2), s(0) * s(2), s(0) * s(1));
  Eigen::Matrix3d a = beta(i_c) * s * s.transpose() + lambda_ * c * c.transpose();
  a.diagonal().array() += kappa(i_c);
  a(0, 1) += volume_slope * s(2);
  a(0, 2) += volume_slope * s(1);
  a(1, 2) += volume_slope * s(0);
  a(1, 0) = a(0, 1);
  a(2, 0) = a(0, 2);
  a(2, 1) = a(1, 2);
  return a;
}

HessianEigensystem StableNeoHookean::hessian_eigensystem(const Eigen::Matrix3d& f) const {
  const RotationVariantSvd svd = rotation_variant_svd(f);
  const double k = kappa(svd.s.squaredNorm());
  const double volume_slope = lambda_ * (svd.s.prod() - alpha_);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> scaling(scaling_hessian(svd.s));
  HessianEigensystem out;
  for (int m = 0; m < 3; ++m) {
    out.values(m) = scaling.eigenvalues()(m);
    out.vectors.col(m) =
        vec(svd.u * scaling.eigenvectors().col(m).asDiagonal() * svd.v.transpose());
  }
  const double half_sqrt2 = std::sqrt(0.5);
  for (int p = 0; p < 3; ++p) {
    const Eigen::Matrix3d ab = svd.u.col(kPairs[p][0]) * svd.v.col(kPairs[p][1]).transpose();
    const Eigen::Matrix3d ba = svd.u.col(kPairs[p][1]) * svd.v.col(kPairs[p][0]).transpose();
    const double s_k = svd.s(kPairs[p][2]);
    out.values(3 + 2 * p) = k + volume_slope * s_k;
    out.vectors.col(3 + 2 * p) = half_sqrt2 * vec(ab - ba);
    out.values(4 + 2 * p) = k - volume_slope * s_k;
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
  const RotationVariantSvd svd = rotation_variant_svd(f);
  const double k = kappa(svd.s.squaredNorm());
  const double volume_slope = lambda_ * (svd.s.prod() - alpha_);
  const double half_sqrt2 = std::sqrt(0.5);
  for (int p = 0; p < 3; ++p) {
    const double s_k = svd.s(kPairs[p][2]);
    for (const double sign : {-1.0, 1.0}) {  // twist, flip
      const double value = k - sign * volume_slope * s_k;
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
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> scaling(a);
    for (int m = 0; m < 3; ++m) {
      const double value = scaling.eigenvalues()(m);
      if (value >= 0.0) continue;
      const Vector9d q =
          vec(svd.u * scaling.eigenvectors().col(m).asDiagonal() * svd.v.transpose());
      h.noalias() -= value * q * q.transpose();
    }
  }
  return h;
}

const char* validate_stable_neo_hookean(const Material& material, StableNeoHookeanOptions options) {
  const char* error = validate(material);
  if (error[0] != '\0') return error;
  // lambda <= 0 would make the volume term concave (or absent) and alpha
  // infinite; it happens when the Yeoh term's bulk share, 8 c20, exceeds
  // what the small-strain lambda has to give (low nu, high C20/C10).
  if (!(map_parameters(material, options.log_term).lambda > 0.0)) {
    return "material.poisson_ratio too low for material.yeoh_c20_over_c10: the Stable "
           "Neo-Hookean lambda would be <= 0";
  }
  return "";
}

}  // namespace fahr::fem
