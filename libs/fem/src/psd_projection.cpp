// 9x9 PSD projection by eigen-decomposition.
#include "fahr/fem/psd_projection.h"

#include <Eigen/Eigenvalues>

namespace fahr::fem {

Matrix9d project_to_psd(const Matrix9d& h) {
  const Eigen::SelfAdjointEigenSolver<Matrix9d> eigen(h);
  return eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).asDiagonal() *
         eigen.eigenvectors().transpose();
}

}  // namespace fahr::fem
