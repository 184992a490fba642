// Stable Neo-Hookean with the Yeoh term, at the material level: no stress in
// rotation, linear elasticity at small strain, stress and Hessian equal to
// central differences (inverted F included), the analytic eigensystem equal
// to a numerical one, a positive semi-definite projection, confined
// compression resisted through J = 0, and the mapping from E and nu.
#include "fahr/fem/stable_neo_hookean.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "fahr/fem/psd_projection.h"

namespace fahr::fem {
namespace {

// The tongue (E from the adult MRE shear modulus, nu = 0.45) with and without
// the Yeoh term, with and without the log term: every test runs all four.
struct Variant {
  const char* name;
  double yeoh_ratio;
  bool log_term;
};

constexpr Variant kVariants[] = {
    {"snh", 0.0, true},
    {"snh+yeoh", kTongueYeohC20OverC10, true},
    {"snh-no-log", 0.0, false},
    {"snh-no-log+yeoh", kTongueYeohC20OverC10, false},
};

Material tongue(double yeoh_ratio) {
  Material m = neonatal_tongue();
  m.yeoh_c20_over_c10 = yeoh_ratio;
  return m;
}

StableNeoHookean make(const Variant& v) {
  StableNeoHookeanOptions options;
  options.log_term = v.log_term;
  EXPECT_STREQ(validate(tongue(v.yeoh_ratio)), "");
  return StableNeoHookean(tongue(v.yeoh_ratio), options);
}

Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

// Random deformation gradients: stretches in [0.3, 1.8] between two random
// rotations, every third one inverted (one stretch negated), plus a raw
// random matrix every fourth (general, often badly conditioned).
std::vector<Eigen::Matrix3d> random_deformations(int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> stretch(0.3, 1.8);
  std::uniform_real_distribution<double> entry(-1.5, 1.5);
  std::vector<Eigen::Matrix3d> out;
  for (int n = 0; n < count; ++n) {
    Eigen::Matrix3d f;
    if (n % 4 == 3) {
      for (int k = 0; k < 9; ++k) f(k) = entry(rng);
    } else {
      Eigen::Vector3d s(stretch(rng), stretch(rng), stretch(rng));
      if (n % 3 == 2) s(n % 3) = -s(n % 3);
      f = random_rotation(rng) * s.asDiagonal() * random_rotation(rng).transpose();
    }
    out.push_back(f);
  }
  return out;
}

// The stress scale of the material: the P-wave modulus lambda_LE + 2 mu_LE.
double stress_scale(const Material& m) {
  const LameParameters lame = lame_parameters(m);
  return lame.lambda_pa + 2.0 * lame.mu_pa;
}

TEST(StableNeoHookean, RigidRotationGivesNoEnergyAndNoStress) {
  std::mt19937 rng(7);
  for (const Variant& v : kVariants) {
    const StableNeoHookean snh = make(v);
    const double scale = stress_scale(tongue(v.yeoh_ratio));
    EXPECT_NEAR(snh.energy_density(Eigen::Matrix3d::Identity()), 0.0, 1e-12 * scale) << v.name;
    for (int n = 0; n < 50; ++n) {
      const Eigen::Matrix3d r = random_rotation(rng);
      EXPECT_LT(std::abs(snh.energy_density(r)), 1e-12 * scale) << v.name;
      EXPECT_LT(snh.first_piola(r).norm(), 1e-12 * scale) << v.name;
    }
  }
}

// Linear elasticity from E and nu, written here from the textbook formulas.
Eigen::Matrix3d linear_elastic_stress(double e, double nu, const Eigen::Matrix3d& grad_u) {
  const double mu = e / (2.0 * (1.0 + nu));
  const double lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  const Eigen::Matrix3d strain = 0.5 * (grad_u + grad_u.transpose());
  return 2.0 * mu * strain + lambda * strain.trace() * Eigen::Matrix3d::Identity();
}

TEST(StableNeoHookean, SmallStrainStressIsLinearElastic) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> entry(-1.0, 1.0);
  // Relative error: O(eps) from the nonlinearity, O(1e-16 / eps) from the
  // cancellation of kappa F against lambda (J - alpha) cof F; eps = 1e-5
  // keeps both far below 1e-3.
  const double eps = 1e-5;
  for (const Variant& v : kVariants) {
    const StableNeoHookean snh = make(v);
    const Material m = tongue(v.yeoh_ratio);
    for (int n = 0; n < 20; ++n) {
      Eigen::Matrix3d g;
      for (int k = 0; k < 9; ++k) g(k) = entry(rng);
      const Eigen::Matrix3d p = snh.first_piola(Eigen::Matrix3d::Identity() + eps * g);
      const Eigen::Matrix3d linear =
          linear_elastic_stress(m.youngs_modulus_pa, m.poisson_ratio, eps * g);
      EXPECT_LT((p - linear).norm() / linear.norm(), 1e-3) << v.name << " sample " << n;
    }
  }
}

// Central differences: Psi for P, P for H. With F of order 1 a step of 1e-5
// leaves a truncation error near 1e-10 and a round-off error near 1e-11,
// relative.
constexpr double kStep = 1e-5;

TEST(StableNeoHookean, StressIsTheEnergyGradient) {
  const std::vector<Eigen::Matrix3d> fs = random_deformations(40, 3);
  for (const Variant& v : kVariants) {
    const StableNeoHookean snh = make(v);
    for (std::size_t n = 0; n < fs.size(); ++n) {
      const Eigen::Matrix3d& f = fs[n];
      Eigen::Matrix3d numeric;
      for (int k = 0; k < 9; ++k) {
        Eigen::Matrix3d plus = f, minus = f;
        plus(k) += kStep;
        minus(k) -= kStep;
        numeric(k) = (snh.energy_density(plus) - snh.energy_density(minus)) / (2.0 * kStep);
      }
      const Eigen::Matrix3d p = snh.first_piola(f);
      EXPECT_LT((numeric - p).norm() / p.norm(), 1e-5)
          << v.name << " det F " << f.determinant() << " sample " << n;
    }
  }
}

TEST(StableNeoHookean, HessianIsTheStressDerivative) {
  const std::vector<Eigen::Matrix3d> fs = random_deformations(40, 5);
  int inverted = 0;
  for (const Variant& v : kVariants) {
    const StableNeoHookean snh = make(v);
    for (std::size_t n = 0; n < fs.size(); ++n) {
      const Eigen::Matrix3d& f = fs[n];
      Matrix9d numeric;
      for (int k = 0; k < 9; ++k) {
        Eigen::Matrix3d plus = f, minus = f;
        plus(k) += kStep;
        minus(k) -= kStep;
        numeric.col(k) = vec(snh.first_piola(plus) - snh.first_piola(minus)) / (2.0 * kStep);
      }
      const Matrix9d h = snh.hessian(f);
      EXPECT_LT((numeric - h).norm() / h.norm(), 1e-5)
          << v.name << " det F " << f.determinant() << " sample " << n;
      EXPECT_LT((h - h.transpose()).norm(), 1e-12 * h.norm());
      if (f.determinant() < 0.0) ++inverted;
    }
  }
  EXPECT_GT(inverted, 20);  // the samples do cover inverted elements
}

TEST(StableNeoHookean, AnalyticEigensystemIsTheHessians) {
  const std::vector<Eigen::Matrix3d> fs = random_deformations(40, 9);
  for (const Variant& v : kVariants) {
    const StableNeoHookean snh = make(v);
    for (std::size_t n = 0; n < fs.size(); ++n) {
      const Matrix9d h = snh.hessian(fs[n]);
      const HessianEigensystem eigen = snh.hessian_eigensystem(fs[n]);
      const double scale = h.norm();
      EXPECT_LT((eigen.vectors.transpose() * eigen.vectors - Matrix9d::Identity()).norm(), 1e-12)
          << v.name << " sample " << n;
      const Matrix9d rebuilt =
          eigen.vectors * eigen.values.asDiagonal() * eigen.vectors.transpose();
      EXPECT_LT((rebuilt - h).norm(), 1e-10 * scale) << v.name << " sample " << n;
      Vector9d analytic = eigen.values;
      std::sort(analytic.begin(), analytic.end());
      const Vector9d numeric = Eigen::SelfAdjointEigenSolver<Matrix9d>(h).eigenvalues();
      EXPECT_LT((analytic - numeric).norm(), 1e-10 * scale) << v.name << " sample " << n;
    }
  }
}

double smallest_eigenvalue(const Matrix9d& h) {
  return Eigen::SelfAdjointEigenSolver<Matrix9d>(h, Eigen::EigenvaluesOnly).eigenvalues()(0);
}

TEST(StableNeoHookean, ProjectedHessianIsPositiveSemiDefinite) {
  const std::vector<Eigen::Matrix3d> fs = random_deformations(60, 13);
  int indefinite = 0;
  for (const Variant& v : kVariants) {
    const StableNeoHookean snh = make(v);
    for (std::size_t n = 0; n < fs.size(); ++n) {
      const Matrix9d h = snh.hessian(fs[n]);
      const double scale = h.norm();
      if (smallest_eigenvalue(h) < -1e-9 * scale) ++indefinite;
      const Matrix9d analytic = snh.projected_hessian(fs[n]);
      const Matrix9d numeric = project_to_psd(h);
      EXPECT_GE(smallest_eigenvalue(analytic), -1e-9 * scale) << v.name << " sample " << n;
      EXPECT_GE(smallest_eigenvalue(numeric), -1e-9 * scale) << v.name << " sample " << n;
      // The nearest PSD matrix is unique: both routes must find the same one.
      EXPECT_LT((analytic - numeric).norm(), 1e-9 * scale) << v.name << " sample " << n;
    }
  }
  EXPECT_GT(indefinite, 40);  // the projection had work to do
  // In moderate tension the Hessian is positive definite and the projection
  // leaves it alone. (Not so in compression, however small: the twists of a
  // compressed element, rotations against the stress, have negative
  // curvature, which the projection removes.)
  std::mt19937 rng(17);
  for (const Variant& v : kVariants) {
    const StableNeoHookean snh = make(v);
    const Eigen::Matrix3d f = random_rotation(rng) *
                              Eigen::Vector3d(1.03, 1.02, 1.01).asDiagonal() * random_rotation(rng);
    const Matrix9d h = snh.hessian(f);
    EXPECT_GT(smallest_eigenvalue(h), 0.0) << v.name;
    EXPECT_LT((snh.projected_hessian(f) - h).norm(), 1e-12 * h.norm()) << v.name;
    const Eigen::Matrix3d squeezed = Eigen::Vector3d(0.99, 1.0, 1.0).asDiagonal();
    EXPECT_LT(smallest_eigenvalue(snh.hessian(squeezed)), 0.0) << v.name;
  }
}

// Confined compression F = diag(1, 1, s), s from 1 down to 0.2 (80 %) and on
// through J = 0 to an inverted -0.5: the energy grows all the way, the stress
// stays finite and P_zz < 0 pushes back towards s = 1 even when inverted.
TEST(StableNeoHookean, ConfinedCompressionIsResistedThroughInversion) {
  for (const Variant& v : kVariants) {
    const StableNeoHookean snh = make(v);
    double previous_energy = 0.0;
    for (int step = 1; step <= 150; ++step) {
      const double s = 1.0 - 0.01 * step;
      const Eigen::Matrix3d f = Eigen::Vector3d(1.0, 1.0, s).asDiagonal();
      const double energy = snh.energy_density(f);
      const Eigen::Matrix3d p = snh.first_piola(f);
      ASSERT_TRUE(std::isfinite(energy) && p.allFinite()) << v.name << " s " << s;
      EXPECT_GT(energy, previous_energy) << v.name << " s " << s;
      EXPECT_LT(p(2, 2), 0.0) << v.name << " s " << s;
      previous_energy = energy;
    }
  }
}

TEST(StableNeoHookean, MappingIsThePapersWhateverTheYeohRatio) {
  for (const double ratio : {0.0, kTongueYeohC20OverC10}) {
    const Material m = tongue(ratio);
    const LameParameters lame = lame_parameters(m);
    const StableNeoHookean with_log(m);
    EXPECT_NEAR(with_log.mu_pa(), 4.0 / 3.0 * lame.mu_pa, 1e-9 * lame.mu_pa);
    EXPECT_NEAR(with_log.lambda_pa(), lame.lambda_pa + 5.0 / 6.0 * lame.mu_pa,
                1e-9 * lame.lambda_pa);
    EXPECT_NEAR(with_log.alpha(),
                1.0 + with_log.mu_pa() / with_log.lambda_pa() -
                    with_log.mu_pa() / (4.0 * with_log.lambda_pa()),
                1e-12);
    EXPECT_NEAR(with_log.yeoh_c20_pa(), ratio * lame.mu_pa / 2.0, 1e-12 * lame.mu_pa);
    StableNeoHookeanOptions no_log;
    no_log.log_term = false;
    const StableNeoHookean without_log(m, no_log);
    EXPECT_NEAR(without_log.mu_pa(), lame.mu_pa, 1e-9 * lame.mu_pa);
    EXPECT_NEAR(without_log.lambda_pa(), lame.lambda_pa + lame.mu_pa, 1e-9 * lame.lambda_pa);
    EXPECT_NEAR(without_log.alpha(), 1.0 + lame.mu_pa / without_log.lambda_pa(), 1e-12);
  }
  // The Yeoh term leaves the small-strain stress alone at any nu, low ones
  // included (it does not borrow from lambda).
  for (const double nu : {0.0, 0.2, 0.49}) {
    Material m = tongue(kTongueYeohC20OverC10);
    m.poisson_ratio = nu;
    const StableNeoHookean snh(m);
    Eigen::Matrix3d g;
    g << 0.3, -0.7, 0.2, 0.5, -0.4, 0.9, -0.1, 0.6, 0.8;
    const double eps = 1e-5;
    const Eigen::Matrix3d linear = linear_elastic_stress(m.youngs_modulus_pa, nu, eps * g);
    const Eigen::Matrix3d p = snh.first_piola(Eigen::Matrix3d::Identity() + eps * g);
    EXPECT_LT((p - linear).norm() / linear.norm(), 1e-3) << "nu " << nu;
  }
}

}  // namespace
}  // namespace fahr::fem
