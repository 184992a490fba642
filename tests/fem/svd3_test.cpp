// The fast 3x3 SVD: a factorisation of F with rotations U, V and the
// rotation-variant singular values, as accurate as Eigen's JacobiSVD on
// random, inverted, flat, degenerate and repeated-value matrices; and its
// cost against JacobiSVD.
#include "fahr/fem/svd3.h"

#include <gtest/gtest.h>
#include <time.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
// GCC 13 reports JacobiSVD's singular values of a fixed 3x3 as maybe
// uninitialised at -O3 (they are written by compute()).
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <Eigen/SVD>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace fahr::fem {
namespace {

Eigen::Matrix3d random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::Quaterniond q(normal(rng), normal(rng), normal(rng), normal(rng));
  return q.normalized().toRotationMatrix();
}

// Matrices U diag(s) V^T with chosen singular values: general, repeated,
// tiny, zero and negative (inverted).
std::vector<Eigen::Matrix3d> test_matrices() {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::vector<Eigen::Matrix3d> out;
  for (int n = 0; n < 200; ++n) {
    Eigen::Matrix3d m;
    for (int k = 0; k < 9; ++k) m(k) = uniform(rng);
    out.push_back(m);
    out.push_back(Eigen::Matrix3d::Identity() + 0.3 * m);
  }
  const std::vector<Eigen::Vector3d> spectra = {
      {1.0, 1.0, 1.0},  {2.0, 1.0, 1.0},   {1.0, 1.0, 0.5},  {1.0, 1.0, -0.5},
      {1.0, 0.5, 1e-9}, {1.0, 0.5, -1e-9}, {1.0, 0.5, 0.0},  {1.0, 0.0, 0.0},
      {0.0, 0.0, 0.0},  {3.0, 2.0, -1.0},  {1.0, 1.0, -1.0}, {1e-8, 1e-8, 1e-8}};
  for (const Eigen::Vector3d& s : spectra) {
    for (int n = 0; n < 20; ++n) {
      out.push_back(random_rotation(rng) * s.asDiagonal() * random_rotation(rng).transpose());
    }
    out.push_back(s.asDiagonal());
  }
  return out;
}

TEST(Svd3, FactorsWithRotationsAndSignedSingularValues) {
  for (const Eigen::Matrix3d& f : test_matrices()) {
    const Svd3 svd = rotation_variant_svd(f);
    const double scale = std::max(f.norm(), 1e-300);
    EXPECT_LT((svd.u * svd.s.asDiagonal() * svd.v.transpose() - f).norm(), 1e-13 * scale) << f;
    EXPECT_LT((svd.u.transpose() * svd.u - Eigen::Matrix3d::Identity()).norm(), 1e-13);
    EXPECT_LT((svd.v.transpose() * svd.v - Eigen::Matrix3d::Identity()).norm(), 1e-13);
    EXPECT_NEAR(svd.u.determinant(), 1.0, 1e-13);
    EXPECT_NEAR(svd.v.determinant(), 1.0, 1e-13);
    EXPECT_GE(svd.s(0), svd.s(1) - 1e-14 * scale);
    EXPECT_GE(svd.s(1), std::abs(svd.s(2)) - 1e-14 * scale);
    // The same values as Eigen's, the sign of det F on the smallest.
    const Eigen::JacobiSVD<Eigen::Matrix3d> reference(f);
    Eigen::Vector3d expected = reference.singularValues();
    if (f.determinant() < 0.0) expected(2) = -expected(2);
    EXPECT_LT((svd.s - expected).norm(), 1e-13 * scale) << f;
  }
}

TEST(Svd3, SymmetricEigenSolveIsExact) {
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int n = 0; n < 200; ++n) {
    Eigen::Matrix3d m;
    for (int k = 0; k < 9; ++k) m(k) = uniform(rng);
    const Eigen::Matrix3d a = n % 2 == 0 ? Eigen::Matrix3d(m + m.transpose())
                                         : Eigen::Matrix3d(Eigen::Matrix3d::Identity());
    Eigen::Vector3d values;
    Eigen::Matrix3d vectors;
    symmetric_eigen3(a, values, vectors);
    EXPECT_LT((vectors * values.asDiagonal() * vectors.transpose() - a).norm(), 1e-14 * a.norm());
    EXPECT_LE(values(0), values(1));
    EXPECT_LE(values(1), values(2));
    EXPECT_NEAR(vectors.determinant(), 1.0, 1e-13);
  }
}

double thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e9 * static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec);
}

// Prints the cost of both; asserts nothing about time.
TEST(Svd3, CostAgainstJacobiSvd) {
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> uniform(-0.3, 0.3);
  std::vector<Eigen::Matrix3d> fs;
  for (int n = 0; n < 4000; ++n) {
    Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
    for (int k = 0; k < 9; ++k) m(k) += uniform(rng);
    if (n % 4 == 3) m.col(0) = -m.col(0);
    fs.push_back(random_rotation(rng) * m);
  }
  double sink = 0.0;
  auto best = [&](auto work) {
    double ns = 1e300;
    for (int pass = 0; pass < 7; ++pass) {
      const double start = thread_cpu_ns();
      for (const Eigen::Matrix3d& f : fs) sink += work(f);
      ns = std::min(ns, (thread_cpu_ns() - start) / static_cast<double>(fs.size()));
    }
    return ns;
  };
  const double fast = best([](const Eigen::Matrix3d& f) {
    const Svd3 svd = rotation_variant_svd(f);
    return svd.u(1, 2) + svd.v(2, 1) + svd.s(2);
  });
  const double eigen = best([](const Eigen::Matrix3d& f) {
    const Eigen::JacobiSVD<Eigen::Matrix3d, Eigen::NoQRPreconditioner> svd(
        f, Eigen::ComputeFullU | Eigen::ComputeFullV);
    return svd.matrixU()(1, 2) + svd.matrixV()(2, 1) + svd.singularValues()(2);
  });
  std::printf(
      "3x3 SVD, thread CPU ns (best of 7 passes over %zu, a quarter inverted): "
      "rotation_variant_svd %.0f, Eigen JacobiSVD %.0f\n",
      fs.size(), fast, eigen);
  EXPECT_TRUE(std::isfinite(sink));
}

}  // namespace
}  // namespace fahr::fem

#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
