// The FEM side of the in-process lockstep: one fem::Body stepped as the FEM
// service does (implicit Euler, then the Algorithm 1 projection of the
// newest ContactSet), split in two phases so the free-motion sphere centres
// the contact solve needs are available (README, "Which centre"):
//   1. Body::step without contacts: the free motion x_free;
//   2. fem::project_contacts on a copy: x~, written back to the body;
//   3. the velocity correction (x~ - x_free)/h of Algorithm 1 is carried
//      into the next step as an impulse, f = m (x~ - x_free)/h^2 on each
//      moved node, so the next right-hand side is M (v + dx/h) + h f, exactly
//      Algorithm 1's.
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
#include "fahr/fem/element_rest.h"
#include "fahr/fem/sphere_links.h"

namespace fahr::contact::sim {

struct FemDriverSettings {
  fem::BodySettings body;
  // Recompute W every step (exact for refactor_period 1); with
  // refactor_period 0 the factor never changes and W is computed once.
  bool recompute_compliance = false;
  // Apply the ContactSet's forces (lambda along n, through the sphere
  // weights) in the implicit step before the projection (README, "What the
  // FEM must do with lambda"). false: the projection alone, as Algorithm 1.
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
  static std::unique_ptr<FemDriver> create(const FemDriverSettings& settings, const fem::TetMesh& mesh,
                                           std::span<const std::uint32_t> fixed_nodes, fem::SphereLinks links,
                                           std::span<const std::uint32_t> compliance_spheres, std::string& error);

  // One FEM step with the given contacts (may be null) and external nodal
  // forces (3 per node, N; empty for none).
  FemStepReport step(const fem::ContactSet* contacts, std::span<const double> external_forces_n);

  const fem::SphereLinks& links() const { return links_; }
  std::span<const Eigen::Vector3d> free_centres() const { return free_centres_; }
  std::span<const Eigen::Vector3d> centres() const { return centres_; }
  std::span<const double> radii() const { return radii_; }
  std::span<const std::int32_t> compliance_index() const { return compliance_index_; }
  std::span<const std::uint32_t> compliance_spheres() const { return compliance_spheres_; }
  std::span<const float> compliance() const { return compliance_; }
  std::uint64_t step_index() const { return body_->step_index(); }
  fem::Body& body() { return *body_; }
  std::span<const double> positions_m() const { return body_->positions_m(); }

  // Largest node displacement from rest, m.
  double max_displacement_m() const;
  // Largest Green strain norm |(F^T F - I)/2|_F over the tets.
  double max_strain() const;
  // Count of tets with det F <= 0 now.
  int inverted_now() const;

 private:
  FemDriver() = default;
  void update_centres(std::vector<Eigen::Vector3d>& out) const;

  FemDriverSettings settings_;
  std::unique_ptr<fem::Body> body_;
  fem::SphereLinks links_;
  fem::ElementRest rest_;
  std::vector<Eigen::Vector3d> free_centres_, centres_;
  std::vector<double> radii_;
  std::vector<std::int32_t> compliance_index_;
  std::vector<std::uint32_t> compliance_spheres_;
  std::vector<float> compliance_;
  std::vector<double> projected_;
  std::vector<double> applied_lambda_;           // per compliance sphere, N
  std::vector<Eigen::Vector3d> applied_normal_;  // per compliance sphere
  std::vector<double> carry_n_;  // Algorithm 1 velocity correction as next-step force, N
  bool compliance_ready_ = false;
};

// One sphere per node, weight 1, radius r: the node is the sphere centre.
// The simplest exact sphere-to-tissue map for a test surface.
fem::SphereLinks make_node_spheres(std::span<const std::uint32_t> nodes, double radius_m);

}  // namespace fahr::contact::sim
