// One FEM service step with the contact contract (DESIGN.md, and
// services/contact/README.md "Which centre" and "What the FEM must do with
// lambda"):
//   1. the haptic solve's contact forces (lambda along n, through each
//      sphere's node weights) and the carried Algorithm 1 correction act as
//      external forces in the implicit step: the free motion;
//   2. the compliance W of the spheres the haptic service works with, and
//      their free-motion centres c_free = c - W N lambda;
//   3. the Algorithm 1 projection of the ContactSet on the free motion,
//      written back to the body; its velocity correction (x~ - x_free)/h is
//      carried into the next step as the nodal force m (x~ - x_free)/h^2,
//      which gives exactly Algorithm 1's next right-hand side.
// Everything is sized at construction: nothing allocates per step once the
// compliance block has reached its largest size.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "fahr/fem/body.h"
#include "fahr/fem/projection.h"
#include "fahr/fem/sphere_links.h"

namespace fahr::fem_service {

class ContactStep {
 public:
  ContactStep(fem::Body& body, const fem::SphereLinks& links, std::size_t max_compliance_spheres);

  // `contacts` may be null (no ContactSet yet).
  fem::StepReport step(const fem::ContactSet* contacts);

  // Spheres of the last step's compliance block, its W (row-major 3k x 3k,
  // m/N) and their free-motion centres (3 per sphere, m).
  const std::vector<std::uint32_t>& compliance_spheres() const { return spheres_; }
  const std::vector<float>& compliance() const { return compliance_; }
  const std::vector<float>& free_centres() const { return free_centres_; }
  const fem::ProjectionReport& projection() const { return projection_; }
  // Steps that reused the previous compliance block instead of solving.
  std::uint64_t compliance_reuses() const { return compliance_reuses_; }

 private:
  void apply_forces(const fem::ContactSet* contacts);
  void compute_compliance(const fem::ContactSet* contacts, bool refactorised);
  void project(const fem::ContactSet& contacts);

  fem::Body& body_;
  const fem::SphereLinks& links_;
  std::size_t capacity_;
  std::vector<double> carry_n_;    // carried Algorithm 1 correction, N per DOF
  std::vector<double> force_n_;    // this step's external force, N per DOF
  std::vector<double> projected_;  // projection workspace, m per DOF
  std::vector<std::uint32_t> spheres_;
  std::vector<double> lambda_n_;   // lambda applied per compliance sphere, N
  std::vector<Eigen::Vector3d> normals_;
  std::vector<float> compliance_;
  // W depends only on the factorisation: with the same spheres and no
  // refactorisation since, the last block is still exact and is reused.
  std::vector<std::uint32_t> compliance_of_;
  bool compliance_valid_ = false;
  std::uint64_t compliance_reuses_ = 0;
  std::vector<float> free_centres_;
  fem::ProjectionReport projection_;
};

}  // namespace fahr::fem_service
