// Two-phase FEM stepping with free-motion centres and Algorithm 1 velocities.
#include "fahr/contact/sim/fem_driver.h"

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "fahr/fem/projection.h"

namespace fahr::contact::sim {

fem::SphereLinks make_node_spheres(std::span<const std::uint32_t> nodes, double radius_m) {
  fem::SphereLinks links;
  const double weight = 1.0;
  for (const std::uint32_t node : nodes) links.add_sphere({&node, 1}, {&weight, 1}, radius_m);
  return links;
}

std::unique_ptr<FemDriver> FemDriver::create(const FemDriverSettings& settings, const fem::TetMesh& mesh,
                                             std::span<const std::uint32_t> fixed_nodes, fem::SphereLinks links,
                                             std::span<const std::uint32_t> compliance_spheres, std::string& error) {
  std::unique_ptr<FemDriver> driver(new FemDriver());
  driver->settings_ = settings;
  // Sleep is off: a sleeping body skips the free step the solve reads.
  driver->settings_.body.sleep.enabled = false;
  driver->settings_.body.max_compliance_spheres = std::max(settings.body.max_compliance_spheres, compliance_spheres.size());
  fem::BodyOrError made = fem::Body::create(driver->settings_.body, mesh.nodes_m, mesh.tets, fixed_nodes);
  if (!made.body) {
    error = made.error;
    return nullptr;
  }
  driver->body_ = std::move(made.body);
  error = fem::build_element_rest(mesh.nodes_m, mesh.tets, driver->rest_);
  if (!error.empty()) return nullptr;
  driver->links_ = std::move(links);
  const std::size_t spheres = driver->links_.size();
  driver->radii_.resize(spheres);
  for (std::size_t s = 0; s < spheres; ++s) driver->radii_[s] = driver->links_.radius_m(s);
  driver->compliance_index_.assign(spheres, kNoCompliance);
  driver->compliance_spheres_.assign(compliance_spheres.begin(), compliance_spheres.end());
  for (std::size_t i = 0; i < compliance_spheres.size(); ++i) {
    driver->compliance_index_[compliance_spheres[i]] = static_cast<std::int32_t>(i);
  }
  const std::size_t rows = 3 * compliance_spheres.size();
  driver->compliance_.assign(rows * rows, 0.0f);
  driver->projected_.assign(3 * mesh.nodes_m.size(), 0.0);
  driver->carry_n_.assign(3 * mesh.nodes_m.size(), 0.0);
  driver->applied_lambda_.assign(compliance_spheres.size(), 0.0);
  driver->applied_normal_.assign(compliance_spheres.size(), Eigen::Vector3d::Zero());
  driver->update_centres(driver->free_centres_);
  driver->centres_ = driver->free_centres_;
  if (!driver->body_->compliance(driver->compliance_spheres_, driver->links_, driver->compliance_)) {
    error = "compliance of the candidate spheres failed";
    return nullptr;
  }
  driver->compliance_ready_ = true;
  return driver;
}

void FemDriver::update_centres(std::vector<Eigen::Vector3d>& out) const {
  out.resize(links_.size());
  const double* x = body_->positions_m().data();
  for (std::size_t s = 0; s < links_.size(); ++s) out[s] = links_.centre(s, x);
}

FemStepReport FemDriver::step(const fem::ContactSet* contacts, std::span<const double> external_forces_n) {
  fem::Body& body = *body_;
  const std::size_t nodes = body.node_count();
  // The haptic solve's contact forces on tool contacts, J^T n lambda, join
  // the carried Algorithm 1 velocity correction and the caller's forces.
  std::fill(applied_lambda_.begin(), applied_lambda_.end(), 0.0);
  if (settings_.apply_contact_forces && contacts != nullptr) {
    for (const fem::Contact& c : contacts->contacts) {
      if (c.kind != fem::ContactKind::kTool || c.state == fem::ContactState::kCandidate || !(c.force_n > 0.0)) continue;
      if (c.sphere_id >= links_.size()) continue;
      const auto sphere_nodes = links_.nodes(c.sphere_id);
      const auto weights = links_.weights(c.sphere_id);
      for (std::size_t m = 0; m < sphere_nodes.size(); ++m) {
        for (std::size_t d = 0; d < 3; ++d) {
          carry_n_[3 * std::size_t{sphere_nodes[m]} + d] += weights[m] * c.force_n * c.normal[static_cast<Eigen::Index>(d)];
        }
      }
      const std::int32_t index = compliance_index_[c.sphere_id];
      if (index != kNoCompliance) applied_lambda_[static_cast<std::size_t>(index)] = c.force_n;
      if (index != kNoCompliance) applied_normal_[static_cast<std::size_t>(index)] = c.normal;
    }
  }
  body.clear_external_forces();
  for (std::size_t n = 0; n < nodes; ++n) {
    Eigen::Vector3d f(carry_n_[3 * n], carry_n_[3 * n + 1], carry_n_[3 * n + 2]);
    if (!external_forces_n.empty()) {
      f += Eigen::Vector3d(external_forces_n[3 * n], external_forces_n[3 * n + 1], external_forces_n[3 * n + 2]);
    }
    if (f.squaredNorm() > 0.0) body.set_external_force(static_cast<std::uint32_t>(n), f);
  }
  std::fill(carry_n_.begin(), carry_n_.end(), 0.0);

  FemStepReport report;
  const fem::StepReport step = body.step(nullptr, nullptr);
  report.inverted_elements = step.inverted_elements;
  report.solve_failed = step.solve_failed;
  update_centres(free_centres_);
  // The motion without this step's contact forces: x_free = x - h^2 A^-1
  // J^T N lambda, so c_free = c - W N lambda (exact on the same factor).
  const std::size_t k = compliance_spheres_.size();
  for (std::size_t s = 0; s < k; ++s) {
    Eigen::Vector3d shift = Eigen::Vector3d::Zero();
    for (std::size_t t = 0; t < k; ++t) {
      if (applied_lambda_[t] == 0.0) continue;
      for (std::size_t d = 0; d < 3; ++d) {
        const float* row = compliance_.data() + (3 * s + d) * 3 * k + 3 * t;
        shift[static_cast<Eigen::Index>(d)] += applied_lambda_[t] * (double{row[0]} * applied_normal_[t].x() +
                                                                     double{row[1]} * applied_normal_[t].y() +
                                                                     double{row[2]} * applied_normal_[t].z());
      }
    }
    free_centres_[compliance_spheres_[s]] -= shift;
  }

  const std::span<const double> x_free = body.positions_m();
  if (contacts != nullptr && !contacts->contacts.empty()) {
    std::copy(x_free.begin(), x_free.end(), projected_.begin());
    report.projection = fem::project_contacts(*contacts, links_, body.inverse_mass_per_kg(),
                                              settings_.body.projection, projected_);
    const double h2 = body.time_step_s() * body.time_step_s();
    for (std::size_t n = 0; n < nodes; ++n) {
      const Eigen::Vector3d moved(projected_[3 * n] - x_free[3 * n], projected_[3 * n + 1] - x_free[3 * n + 1],
                                  projected_[3 * n + 2] - x_free[3 * n + 2]);
      if (moved.squaredNorm() == 0.0) continue;
      const auto node = static_cast<std::uint32_t>(n);
      body.set_node_position(node, Eigen::Vector3d(projected_[3 * n], projected_[3 * n + 1], projected_[3 * n + 2]));
      const Eigen::Vector3d carry = body.mass_kg()[n] * moved / h2;
      for (std::size_t d = 0; d < 3; ++d) carry_n_[3 * n + d] = carry[static_cast<Eigen::Index>(d)];
    }
  }
  update_centres(centres_);
  if (settings_.recompute_compliance || !compliance_ready_) {
    compliance_ready_ = body.compliance(compliance_spheres_, links_, compliance_);
  }
  report.step = body.step_index();
  const std::span<const double> x = body.positions_m();
  report.finite = std::all_of(x.begin(), x.end(), [](double v) { return std::isfinite(v); });
  return report;
}

double FemDriver::max_displacement_m() const {
  double largest = 0.0;
  for (std::size_t n = 0; n < body_->node_count(); ++n) {
    const auto node = static_cast<std::uint32_t>(n);
    largest = std::max(largest, (body_->position(node) - body_->rest_position(node)).norm());
  }
  return largest;
}

namespace {

Eigen::Matrix3d deformation_gradient(const fem::ElementRest& rest, std::size_t e, const double* x) {
  const fem::Tet& tet = rest.tets[e];
  const Eigen::Map<const Eigen::Vector3d> x0(x + 3 * std::size_t{tet[0]});
  Eigen::Matrix3d ds;
  for (Eigen::Index a = 0; a < 3; ++a) {
    ds.col(a) = Eigen::Map<const Eigen::Vector3d>(x + 3 * std::size_t{tet[static_cast<std::size_t>(a + 1)]}) - x0;
  }
  return ds * rest.dm_inv[e];
}

}  // namespace

double FemDriver::max_strain() const {
  double largest = 0.0;
  const double* x = body_->positions_m().data();
  for (std::size_t e = 0; e < rest_.size(); ++e) {
    const Eigen::Matrix3d f = deformation_gradient(rest_, e, x);
    const Eigen::Matrix3d green = 0.5 * (f.transpose() * f - Eigen::Matrix3d::Identity());
    largest = std::max(largest, green.norm());
  }
  return largest;
}

int FemDriver::inverted_now() const {
  int inverted = 0;
  const double* x = body_->positions_m().data();
  for (std::size_t e = 0; e < rest_.size(); ++e) inverted += deformation_gradient(rest_, e, x).determinant() <= 0.0;
  return inverted;
}

}  // namespace fahr::contact::sim
