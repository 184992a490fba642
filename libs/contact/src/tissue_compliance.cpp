// Block access into the row-major float compliance of a DeformationState.
#include "fahr/contact/tissue_compliance.h"

namespace fahr::contact {

Eigen::Vector3d TissueCompliance::column(std::size_t s, std::size_t t,
                                         const Eigen::Vector3d& n_t) const {
  const std::size_t rows = 3 * sphere_ids.size();
  Eigen::Vector3d out;
  if (along_normals()) {
    const std::size_t k = sphere_ids.size();
    const Eigen::Vector3d m_t(normals[3 * t], normals[3 * t + 1], normals[3 * t + 2]);
    const double along = n_t.dot(m_t);
    for (std::size_t d = 0; d < 3; ++d)
      out[static_cast<Eigen::Index>(d)] = along * double{w_mpn[(3 * s + d) * k + t]};
    return out;
  }
  for (std::size_t d = 0; d < 3; ++d) {
    const float* row = w_mpn.data() + (3 * s + d) * rows + 3 * t;
    out[static_cast<Eigen::Index>(d)] =
        double{row[0]} * n_t.x() + double{row[1]} * n_t.y() + double{row[2]} * n_t.z();
  }
  return out;
}

double TissueCompliance::normal_compliance(std::size_t s, const Eigen::Vector3d& n_s, std::size_t t,
                                           const Eigen::Vector3d& n_t) const {
  return n_s.dot(column(s, t, n_t));
}

}  // namespace fahr::contact
