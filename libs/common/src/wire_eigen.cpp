// The one non-trivial wire conversion: a quaternion checked and normalised.
#include "fahr/common/wire_eigen.h"

#include <cmath>

namespace fahr::common {

Eigen::Quaterniond to_unit_quaternion(const msg::Quat& q) {
  Eigen::Quaterniond out = to_eigen(q);
  const double norm = out.norm();
  if (!(norm > 1e-9) || !std::isfinite(norm)) return Eigen::Quaterniond::Identity();
  out.coeffs() /= norm;
  return out;
}

}  // namespace fahr::common
