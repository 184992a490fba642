// The penalty baseline (the paper's Figure 7a): the tool follows the device
// rigidly, each penetrating row pushes with k_p d n, and the tissue receives
// those forces as external nodal forces through the sphere weights. No
// projection, no force awareness: it shows what the force-aware response
// avoids. Allocation-free per tick.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

#include "fahr/contact/contact_response.h"
#include "fahr/contact/contact_row.h"
#include "fahr/contact/force_output.h"
#include "fahr/fem/sphere_links.h"

namespace fahr::contact {

struct PenaltySettings {
  double stiffness_npm = 1000.0;  // k_p per row, N/m, > 0 (scene default)
  std::size_t max_rows = 64;      // rows per tick
};

// Force on a tissue sphere centre, N (world frame).
struct SphereForce {
  std::uint32_t sphere_id = 0;
  Eigen::Vector3d force_n = Eigen::Vector3d::Zero();
};

class PenaltyResponse {
 public:
  explicit PenaltyResponse(const PenaltySettings& settings);

  // rows: measured with the tool at the device pose.
  const ForceOutput& tick(const DeviceSample& device, std::span<const ContactRow> rows,
                          std::uint64_t fem_step);

  std::span<const SphereForce> sphere_forces() const { return {forces_.data(), force_count_}; }
  bool overflow() const { return overflow_; }
  const ForceOutput& output() const { return output_; }

 private:
  PenaltySettings settings_;
  std::vector<SphereForce> forces_;
  std::size_t force_count_ = 0;
  bool overflow_ = false;
  ForceOutput output_;
};

// Node j of sphere i receives w_j F_i (the transpose of c = sum_j w_j x_j,
// so the virtual work matches), added into nodal_forces_n (3 per node, N).
void spread_sphere_forces(std::span<const SphereForce> forces, const fem::SphereLinks& links,
                          std::span<double> nodal_forces_n);

}  // namespace fahr::contact
