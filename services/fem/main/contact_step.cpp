// The FEM service's step under the contact contract.
#include "contact_step.h"

#include <algorithm>

namespace fahr::fem_service {
namespace {
bool carries_force(const fem::Contact& c) {
  return c.kind == fem::ContactKind::kTool && c.state != fem::ContactState::kCandidate && c.force_n > 0.0;
}
}  // namespace

ContactStep::ContactStep(fem::Body& body, const fem::SphereLinks& links, std::size_t max_compliance_spheres)
    : body_(body), links_(links), capacity_(max_compliance_spheres) {
  const std::size_t dofs = 3 * body.node_count();
  carry_n_.assign(dofs, 0.0);
  force_n_.assign(dofs, 0.0);
  projected_.assign(dofs, 0.0);
  spheres_.reserve(capacity_);
  lambda_n_.reserve(capacity_);
  normals_.reserve(capacity_);
  compliance_.reserve(9 * capacity_ * capacity_);
  compliance_of_.reserve(capacity_);
  free_centres_.reserve(3 * capacity_);
}

void ContactStep::apply_forces(const fem::ContactSet* contacts) {
  force_n_ = carry_n_;
  std::fill(carry_n_.begin(), carry_n_.end(), 0.0);
  if (contacts != nullptr) {
    for (const auto& c : contacts->contacts) {
      if (!carries_force(c) || c.sphere_id >= links_.size()) continue;
      const auto nodes = links_.nodes(c.sphere_id);
      const auto weights = links_.weights(c.sphere_id);
      for (std::size_t m = 0; m < nodes.size(); ++m) {
        for (std::size_t d = 0; d < 3; ++d) {
          force_n_[3 * std::size_t{nodes[m]} + d] += weights[m] * c.force_n * c.normal[static_cast<Eigen::Index>(d)];
        }
      }
    }
  }
  body_.clear_external_forces();
  for (std::size_t n = 0; n < body_.node_count(); ++n) {
    const Eigen::Vector3d f(force_n_[3 * n], force_n_[3 * n + 1], force_n_[3 * n + 2]);
    if (f.squaredNorm() > 0.0) body_.set_external_force(static_cast<std::uint32_t>(n), f);
  }
}

void ContactStep::compute_compliance(const fem::ContactSet* contacts, bool refactorised) {
  spheres_.clear();
  lambda_n_.clear();
  normals_.clear();
  if (contacts != nullptr) {
    for (const auto& c : contacts->contacts) {
      if (spheres_.size() >= capacity_) break;
      if (c.sphere_id >= links_.size()) continue;
      if (std::find(spheres_.begin(), spheres_.end(), c.sphere_id) != spheres_.end()) continue;
      spheres_.push_back(c.sphere_id);
      lambda_n_.push_back(carries_force(c) ? c.force_n : 0.0);
      normals_.push_back(c.normal);
    }
  }
  const std::size_t k = spheres_.size();
  free_centres_.resize(3 * k);
  if (k == 0) {
    compliance_.clear();
    return;
  }
  if (compliance_valid_ && !refactorised && spheres_ == compliance_of_) {
    ++compliance_reuses_;
  } else {
    compliance_.resize(9 * k * k);
    compliance_valid_ = body_.compliance(spheres_, links_, compliance_);
    compliance_of_ = spheres_;
    if (!compliance_valid_) {
      spheres_.clear();
      compliance_.clear();
      free_centres_.clear();
      return;
    }
  }
  const double* x = body_.positions_m().data();
  for (std::size_t s = 0; s < k; ++s) {
    Eigen::Vector3d c = links_.centre(spheres_[s], x);
    for (std::size_t t = 0; t < k; ++t) {
      if (lambda_n_[t] == 0.0) continue;
      for (std::size_t d = 0; d < 3; ++d) {
        const float* row = compliance_.data() + (3 * s + d) * 3 * k + 3 * t;
        c[static_cast<Eigen::Index>(d)] -= lambda_n_[t] * (double{row[0]} * normals_[t].x() +
                                                           double{row[1]} * normals_[t].y() +
                                                           double{row[2]} * normals_[t].z());
      }
    }
    for (std::size_t d = 0; d < 3; ++d) free_centres_[3 * s + d] = static_cast<float>(c[static_cast<Eigen::Index>(d)]);
  }
}

void ContactStep::project(const fem::ContactSet& contacts) {
  const auto x_free = body_.positions_m();
  std::copy(x_free.begin(), x_free.end(), projected_.begin());
  projection_ = fem::project_contacts(contacts, links_, body_.inverse_mass_per_kg(), body_.settings().projection,
                                      projected_);
  const double h2 = body_.time_step_s() * body_.time_step_s();
  for (std::size_t n = 0; n < body_.node_count(); ++n) {
    const Eigen::Vector3d moved(projected_[3 * n] - x_free[3 * n], projected_[3 * n + 1] - x_free[3 * n + 1],
                                projected_[3 * n + 2] - x_free[3 * n + 2]);
    if (moved.squaredNorm() == 0.0) continue;
    const auto node = static_cast<std::uint32_t>(n);
    body_.set_node_position(node, Eigen::Vector3d(projected_[3 * n], projected_[3 * n + 1], projected_[3 * n + 2]));
    const Eigen::Vector3d carry = body_.mass_kg()[n] * moved / h2;
    for (std::size_t d = 0; d < 3; ++d) carry_n_[3 * n + d] = carry[static_cast<Eigen::Index>(d)];
  }
}

fem::StepReport ContactStep::step(const fem::ContactSet* contacts) {
  apply_forces(contacts);
  fem::StepReport report = body_.step(nullptr, nullptr);
  compute_compliance(contacts, report.refactorised);
  projection_ = {};
  if (contacts != nullptr && !contacts->contacts.empty()) project(*contacts);
  report.projection = projection_;
  report.contacts_applied = contacts != nullptr;
  return report;
}

}  // namespace fahr::fem_service
