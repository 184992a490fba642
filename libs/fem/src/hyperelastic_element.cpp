// dF/dx, nodal forces and stiffness of one tetrahedron.
#include "fahr/fem/hyperelastic_element.h"

#include "fahr/fem/element_rest.h"

namespace fahr::fem {

Matrix9x12d deformation_gradient_jacobian(const Eigen::Matrix3d& dm_inv) {
  const Eigen::Matrix<double, 3, 4> g = shape_gradients(dm_inv);
  Matrix9x12d df_dx = Matrix9x12d::Zero();
  for (int a = 0; a < 4; ++a) {
    for (int j = 0; j < 3; ++j) {
      for (int i = 0; i < 3; ++i) df_dx(i + 3 * j, 3 * a + i) = g(j, a);
    }
  }
  return df_dx;
}

Vector12d nodal_forces(const Matrix9x12d& df_dx, double volume_m3, const Eigen::Matrix3d& p) {
  return -volume_m3 * (df_dx.transpose() * vec(p));
}

Matrix12d element_stiffness(const Matrix9x12d& df_dx, double volume_m3, const Matrix9d& h) {
  // dF/dx is made of 3x3 blocks g_a[j] I (block row j, block column a), so
  // block (a, b) of J^T H J is sum over j, j' of g_a[j] g_b[j'] H_jj', with
  // H_jj' the 3x3 block (3j, 3j') of H. Summed in that order it takes about
  // 0.6k multiplications where the dense 12x9 * 9x9 * 9x12 product takes
  // 2.3k (five times the time); the result is the same to round-off.
  Eigen::Matrix<double, 3, 4> g;
  for (Eigen::Index a = 0; a < 4; ++a) {
    for (Eigen::Index j = 0; j < 3; ++j) g(j, a) = df_dx(3 * j, 3 * a);
  }
  return element_stiffness(g, volume_m3, h);
}

Matrix12d element_stiffness(const Eigen::Matrix<double, 3, 4>& g, double volume_m3,
                            const Matrix9d& h) {
  // hg[a][k] = sum_j g_a[j] H_jk.
  Eigen::Matrix3d hg[4][3];
  for (Eigen::Index a = 0; a < 4; ++a) {
    for (Eigen::Index k = 0; k < 3; ++k) {
      hg[a][k] = g(0, a) * h.block<3, 3>(0, 3 * k) + g(1, a) * h.block<3, 3>(3, 3 * k) +
                 g(2, a) * h.block<3, 3>(6, 3 * k);
    }
  }
  // H is symmetric, so block (b, a) is block (a, b) transposed.
  Matrix12d k;
  for (Eigen::Index a = 0; a < 4; ++a) {
    for (Eigen::Index b = a; b < 4; ++b) {
      const Eigen::Matrix3d block =
          volume_m3 * (g(0, b) * hg[a][0] + g(1, b) * hg[a][1] + g(2, b) * hg[a][2]);
      k.block<3, 3>(3 * a, 3 * b) = block;
      if (b != a) k.block<3, 3>(3 * b, 3 * a) = block.transpose();
    }
  }
  return k;
}

}  // namespace fahr::fem
