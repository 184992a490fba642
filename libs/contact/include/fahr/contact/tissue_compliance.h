// A read-only view of the contact compliance a DeformationState carries:
// W = h^2 J A^-1 J^T for the listed spheres (fem::Body::compliance layout).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>

namespace fahr::contact {

struct TissueCompliance {
  // FEM step the compliance (and the rows' centres) come from; echoed in
  // ForceOutput::fem_step.
  std::uint64_t fem_step = 0;
  // Spheres in row/column order of W.
  std::span<const std::uint32_t> sphere_ids;
  // W, (3k x 3k) row-major, m/N, k = sphere_ids.size(); block (s, t) is the
  // motion of sphere s over one FEM step per newton on sphere t. With
  // `normals` (3k, the FEM's unit normal of each sphere): W along them,
  // (3k x k), entry (3s + d, t) = (W_st n_t)_d.
  std::span<const float> w_mpn;
  std::span<const float> normals;

  std::size_t size() const { return sphere_ids.size(); }
  bool along_normals() const { return !normals.empty(); }
  bool valid() const {
    const std::size_t k = sphere_ids.size();
    return along_normals() ? normals.size() >= 3 * k && w_mpn.size() >= 3 * k * k
                           : w_mpn.size() >= 9 * k * k;
  }
  // n_s^T W_st n_t, m/N.
  double normal_compliance(std::size_t s, const Eigen::Vector3d& n_s, std::size_t t,
                           const Eigen::Vector3d& n_t) const;
  // W_st n_t, m/N: how sphere s moves per newton along n_t on sphere t.
  // Along normals only n_t's part along the FEM's normal m_t is known:
  // (n_t . m_t) W_st m_t, exact for n_t = +-m_t; the blade turns a tick's
  // normals by a fraction of a degree over one FEM step.
  Eigen::Vector3d column(std::size_t s, std::size_t t, const Eigen::Vector3d& n_t) const;
};

}  // namespace fahr::contact
