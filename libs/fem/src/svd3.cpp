// 3x3 SVD through the Jacobi eigen-solve of F^T F (see svd3.h).
#include "fahr/fem/svd3.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <utility>

namespace fahr::fem {
namespace {

// Zeroes a(p, q) of the symmetric a by the rotation J in the (p, q) plane,
// a <- J^T a J, v <- v J (Golub and Van Loan's symmetric Schur step).
void jacobi_rotate(Eigen::Matrix3d& a, Eigen::Matrix3d& v, int p, int q) {
  const double apq = a(p, q);
  if (apq == 0.0) return;
  const double tau = (a(q, q) - a(p, p)) / (2.0 * apq);
  double t = 0.0;
  double c = 1.0;
  if (std::abs(tau) > 1e8) {
    // A polishing rotation (the start was the closed-form solve): t =
    // 1 / (2 tau) and c = 1 to round-off (the next terms are relatively
    // 1e-16 smaller), with no square root.
    t = 0.5 / tau;
  } else {
    // The smaller of the two roots of t^2 + 2 tau t - 1 = 0 (angle <= pi/4).
    t = (tau >= 0.0 ? 1.0 : -1.0) / (std::abs(tau) + std::sqrt(1.0 + tau * tau));
    c = 1.0 / std::sqrt(1.0 + t * t);
  }
  const double s = t * c;
  const int r = 3 - p - q;  // the third index
  a(p, p) -= t * apq;
  a(q, q) += t * apq;
  a(p, q) = a(q, p) = 0.0;
  const double arp = a(r, p);
  const double arq = a(r, q);
  a(r, p) = a(p, r) = c * arp - s * arq;
  a(r, q) = a(q, r) = s * arp + c * arq;
  for (int k = 0; k < 3; ++k) {
    const double vkp = v(k, p);
    const double vkq = v(k, q);
    v(k, p) = c * vkp - s * vkq;
    v(k, q) = s * vkp + c * vkq;
  }
}

// Any unit vector orthogonal to the unit vector a.
Eigen::Vector3d orthogonal_unit(const Eigen::Vector3d& a) {
  // Cross with the axis a is least aligned with.
  Eigen::Index smallest = 0;
  a.cwiseAbs().minCoeff(&smallest);
  return a.cross(Eigen::Vector3d::Unit(smallest)).normalized();
}

}  // namespace

void symmetric_eigen3(const Eigen::Matrix3d& input, Eigen::Vector3d& values,
                      Eigen::Matrix3d& vectors) {
  // Start from Eigen's closed-form solve (the roots of the characteristic
  // cubic, eigenvectors from cross products): fast, but its vectors can be
  // off by more than round-off where eigenvalues are close or tiny. Jacobi
  // rotations on vectors^T A vectors then take what is left off the
  // diagonal; from that start they are usually tiny (polishing rotations
  // without a square root) and one sweep ends it.
  const Eigen::Matrix3d full = input.selfadjointView<Eigen::Upper>();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> direct;
  direct.computeDirect(full);
  vectors = direct.eigenvectors();
  // Its vectors are orthogonal only to about 1e-9 where eigenvalues are
  // close, and rotations keep that error: orthonormalise first (then the
  // start is a rotation, and so is every iterate).
  vectors.col(0).normalize();
  vectors.col(1) -= vectors.col(0).dot(vectors.col(1)) * vectors.col(0);
  vectors.col(1).normalize();
  vectors.col(2) = vectors.col(0).cross(vectors.col(1));
  if (!vectors.allFinite()) vectors.setIdentity();
  Eigen::Matrix3d a = vectors.transpose() * full * vectors;
  const double scale = full.diagonal().cwiseAbs().sum() +
                       2.0 * (std::abs(full(0, 1)) + std::abs(full(0, 2)) + std::abs(full(1, 2)));
  // Converged when the off-diagonal is round-off against the matrix; a 3x3
  // gets there in three or four sweeps, ten is a safety bound.
  const double tolerance = 1e-16 * scale;
  for (int sweep = 0; sweep < 10; ++sweep) {
    const double off = std::abs(a(0, 1)) + std::abs(a(0, 2)) + std::abs(a(1, 2));
    if (!(off > tolerance)) break;
    jacobi_rotate(a, vectors, 0, 1);
    jacobi_rotate(a, vectors, 0, 2);
    jacobi_rotate(a, vectors, 1, 2);
  }
  values = a.diagonal();
  // Ascending, by a three-element sort that moves the columns along.
  auto order = [&](int i, int j) {
    if (values(i) > values(j)) {
      std::swap(values(i), values(j));
      vectors.col(i).swap(vectors.col(j));
    }
  };
  order(0, 1);
  order(1, 2);
  order(0, 1);
  // The start and the rotations have det = +1; the swaps may have flipped it.
  if (vectors.determinant() < 0.0) vectors.col(0) = -vectors.col(0);
}

Svd3 rotation_variant_svd(const Eigen::Matrix3d& f) {
  Eigen::Vector3d squared;
  Eigen::Matrix3d ascending;
  symmetric_eigen3(f.transpose() * f, squared, ascending);
  Svd3 out;
  // Descending singular values: columns 2, 1, 0 of the ascending solve. The
  // order reversal is an odd permutation, so one column changes sign to keep
  // V a rotation.
  out.v.col(0) = ascending.col(2);
  out.v.col(1) = ascending.col(1);
  out.v.col(2) = -ascending.col(0);
  const Eigen::Vector3d f0 = f * out.v.col(0);
  const Eigen::Vector3d f1 = f * out.v.col(1);
  const double n0 = f0.norm();
  // Below this F is zero to round-off against its own scale.
  const double tiny = 1e-300;
  if (!(n0 > tiny)) {
    out.u.setIdentity();
  } else {
    out.u.col(0) = f0 / n0;
    Eigen::Vector3d u1 = f1 - out.u.col(0).dot(f1) * out.u.col(0);
    const double n1 = u1.norm();
    // F v1 vanishing to round-off of F v0: rank one, any completion works.
    out.u.col(1) = n1 > 1e-12 * n0 ? Eigen::Vector3d(u1 / n1) : orthogonal_unit(out.u.col(0));
    out.u.col(2) = out.u.col(0).cross(out.u.col(1));
  }
  out.s(0) = out.u.col(0).dot(f0);
  out.s(1) = out.u.col(1).dot(f1);
  out.s(2) = out.u.col(2).dot(f * out.v.col(2));
  return out;
}

}  // namespace fahr::fem
