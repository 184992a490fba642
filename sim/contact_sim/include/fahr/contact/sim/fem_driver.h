// The FEM side of the in-process lockstep: one fem::Body stepped as the FEM
// service does, through fem::ContactStep (forces from lambda, free step,
// compliance and free-motion centres, Algorithm 1 projection with its
// velocity correction carried as the next step's force). Adds what the
// harness reads: centres of every sphere (free-motion and projected), the
// compliance index of the candidate spheres, strain and inversion checks.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "fahr/contact/contact_row.h"
#include "fahr/fem/body.h"
#include "fahr/fem/box_mesh.h"
#include "fahr/fem/contact_step.h"
#include "fahr/fem/element_rest.h"
#include "fahr/fem/sphere_links.h"

namespace fahr::contact::sim {

struct FemDriverSettings {
  fem::BodySettings body;
  // Apply the ContactSet's forces (lambda along n, through the sphere
  // weights) in the implicit step before the projection (what the FEM must
  // do with lambda: docs/design/contact-contract.md). false: the projection
  // alone, as Algorithm 1. W follows the factorisation (recomputed when it
  // is refreshed).
  bool apply_contact_forces = true;
};

struct FemStepReport {
  std::uint64_t step = 0;
  int inverted_elements = 0;
  bool finite = true;
  bool solve_failed = false;
  fem::ProjectionReport projection;
};

class FemDriver {
 public:
  // compliance_spheres: the candidate spheres whose W is published (<= the
  // body's max_compliance_spheres). Returns null and sets `error` on failure.
  static std::unique_ptr<FemDriver> create(const FemDriverSettings& settings,
                                           const fem::BodyMesh& mesh,
                                           std::span<const std::uint32_t> fixed_nodes,
                                           fem::SphereLinks links,
                                           std::span<const std::uint32_t> compliance_spheres,
                                           std::string& error);

  // One FEM step with the given contacts (may be null) and external nodal
  // forces (3 per node, N; empty for none).
  FemStepReport step(const fem::ContactSet* contacts, std::span<const double> external_forces_n);

  // Back to rest, as created: the body (rest factorisation), no carried
  // correction, the rest W. Lets one scene serve many independent runs.
  bool reset();

  const fem::SphereLinks& links() const { return links_; }
  std::span<const Eigen::Vector3d> free_centres() const { return free_centres_; }
  std::span<const Eigen::Vector3d> centres() const { return centres_; }
  std::span<const double> radii() const { return radii_; }
  std::span<const std::int32_t> compliance_index() const { return compliance_index_; }
  std::span<const std::uint32_t> compliance_spheres() const {
    return contact_step_->compliance_spheres();
  }
  std::span<const float> compliance() const { return contact_step_->compliance(); }
  const fem::ContactStep& contact_step() const { return *contact_step_; }
  std::uint64_t step_index() const { return body_->step_index(); }
  fem::Body& body() { return *body_; }
  std::span<const double> positions_m() const { return body_->positions_m(); }

  // Largest node displacement from rest, m.
  double max_displacement_m() const;
  // Largest principal Green strain over the tets (fem/strain.h).
  double max_principal_green_strain() const;
  // Count of tets with det F <= 0 now.
  int inverted_now() const;

 private:
  FemDriver() = default;
  void update_centres();

  FemDriverSettings settings_;
  std::unique_ptr<fem::Body> body_;
  fem::SphereLinks links_;
  std::unique_ptr<fem::ContactStep> contact_step_;
  std::vector<Eigen::Vector3d> free_centres_, centres_;
  std::vector<double> radii_;
  std::vector<std::int32_t> compliance_index_;
};

// One sphere per node, weight 1, radius r: the node is the sphere centre.
// The simplest exact sphere-to-tissue map for a test surface.
fem::SphereLinks make_node_spheres(std::span<const std::uint32_t> nodes, double radius_m);

}  // namespace fahr::contact::sim
