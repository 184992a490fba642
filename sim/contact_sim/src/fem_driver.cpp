// Two-phase FEM stepping with free-motion centres and Algorithm 1 velocities.
#include "fahr/contact/sim/fem_driver.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "fahr/fem/strain.h"

namespace fahr::contact::sim {

fem::SphereLinks make_node_spheres(std::span<const std::uint32_t> nodes, double radius_m) {
  fem::SphereLinks links;
  const double weight = 1.0;
  for (const std::uint32_t node : nodes) links.add_sphere({&node, 1}, {&weight, 1}, radius_m);
  return links;
}

std::unique_ptr<FemDriver> FemDriver::create(const FemDriverSettings& settings,
                                             const fem::BodyMesh& mesh,
                                             std::span<const std::uint32_t> fixed_nodes,
                                             fem::SphereLinks links,
                                             std::span<const std::uint32_t> compliance_spheres,
                                             std::string& error) {
  std::unique_ptr<FemDriver> driver(new FemDriver());
  driver->settings_ = settings;
  // Sleep is off: a sleeping body skips the free step the solve reads.
  driver->settings_.body.sleep.enabled = false;
  driver->settings_.body.max_compliance_spheres =
      std::max(settings.body.max_compliance_spheres, compliance_spheres.size());
  fem::BodyOrError made =
      fem::Body::create(driver->settings_.body, mesh.nodes_m, mesh.tets, fixed_nodes);
  if (!made.body) {
    error = made.error;
    return nullptr;
  }
  driver->body_ = std::move(made.body);
  driver->links_ = std::move(links);
  const std::size_t spheres = driver->links_.size();
  driver->radii_.resize(spheres);
  for (std::size_t s = 0; s < spheres; ++s) driver->radii_[s] = driver->links_.radius_m(s);
  driver->compliance_index_.assign(spheres, kNoCompliance);
  for (std::size_t i = 0; i < compliance_spheres.size(); ++i) {
    driver->compliance_index_[compliance_spheres[i]] = static_cast<std::int32_t>(i);
  }
  const fem::ContactStepSettings step{
      .apply_contact_forces = settings.apply_contact_forces,
      .max_compliance_spheres = driver->settings_.body.max_compliance_spheres};
  driver->contact_step_ = std::make_unique<fem::ContactStep>(*driver->body_, driver->links_, step);
  if (!driver->contact_step_->fix_compliance_spheres(compliance_spheres)) {
    error = "compliance of the candidate spheres failed";
    return nullptr;
  }
  driver->update_centres();
  return driver;
}

bool FemDriver::reset() {
  const bool ok = body_->reset_to_rest() && contact_step_->reset();
  update_centres();
  return ok;
}

// Free-motion centres: the compliance spheres' from ContactStep (without
// this step's contact forces); the others', which no solve reads through W,
// of the motion after the implicit step.
void FemDriver::update_centres() {
  const std::size_t spheres = links_.size();
  free_centres_.resize(spheres);
  centres_.resize(spheres);
  const double* x_free = contact_step_->free_positions_m().data();
  const double* x = body_->positions_m().data();
  for (std::size_t s = 0; s < spheres; ++s) {
    free_centres_[s] = links_.centre(s, x_free);
    centres_[s] = links_.centre(s, x);
  }
  const auto ids = contact_step_->compliance_spheres();
  const auto free = contact_step_->free_centres();
  for (std::size_t i = 0; i < ids.size(); ++i) free_centres_[ids[i]] = free[i];
}

FemStepReport FemDriver::step(const fem::ContactSet* contacts,
                              std::span<const double> external_forces_n) {
  FemStepReport report;
  const fem::StepReport step = contact_step_->step(contacts, external_forces_n);
  report.inverted_elements = step.inverted_elements;
  report.solve_failed = step.solve_failed;
  report.projection = step.projection;
  update_centres();
  report.step = body_->step_index();
  const std::span<const double> x = body_->positions_m();
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

double FemDriver::max_principal_green_strain() const {
  return fem::max_principal_green_strain(body_->element_rest(), body_->positions_m());
}

int FemDriver::inverted_now() const {
  return fem::inverted_element_count(body_->element_rest(), body_->positions_m());
}

}  // namespace fahr::contact::sim
