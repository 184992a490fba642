// Penalty forces on penetrating rows, and their spread onto FEM nodes.
#include "fahr/contact/penalty_response.h"

#include <algorithm>

namespace fahr::contact {

PenaltyResponse::PenaltyResponse(const PenaltySettings& settings)
    : settings_(settings), forces_(settings.max_rows) {}

const ForceOutput& PenaltyResponse::tick(const DeviceSample& device,
                                         std::span<const ContactRow> rows, std::uint64_t fem_step) {
  force_count_ = 0;
  overflow_ = false;
  Eigen::Vector3d on_tool = Eigen::Vector3d::Zero();    // sum of row forces on the tool, N
  Eigen::Vector3d on_tissue = Eigen::Vector3d::Zero();  // tissue rows only, N
  Eigen::Matrix3d stiffness = Eigen::Matrix3d::Zero();
  std::uint32_t active = 0;
  for (const ContactRow& row : rows) {
    const double depth = row.penetration_m();
    if (!(depth > 0.0)) continue;
    // The row pushes the other body along +n and the tool along -n.
    const Eigen::Vector3d push = settings_.stiffness_npm * depth * row.normal;
    on_tool -= push;
    stiffness += settings_.stiffness_npm * row.normal * row.normal.transpose();
    ++active;
    if (row.kind != RowKind::kTissue) continue;
    on_tissue += push;
    if (force_count_ == forces_.size()) {
      overflow_ = true;
      continue;
    }
    forces_[force_count_++] = SphereForce{row.id, push};
  }
  ForceOutput& out = output_;
  out.answered_pose_seq = device.pose_seq;
  out.answered_position_m = device.position_m;
  out.force_n = on_tool;
  // Many rows add up to k_p each; the device renders at most its stable
  // stiffness, so the reported local stiffness is scaled down to it.
  const double largest = stiffness.norm();
  out.stiffness_npm = largest > device.max_stiffness_npm
                          ? Eigen::Matrix3d(stiffness * (device.max_stiffness_npm / largest))
                          : stiffness;
  out.proxy_position_m = device.position_m;  // the tool follows the device rigidly
  out.proxy_orientation = device.orientation;
  out.lost_track = on_tool.norm() > device.renderable_force_n;  // reported: nothing reacts to it
  out.device_minus_proxy_m = Eigen::Vector3d::Zero();
  out.tissue_reaction_n = on_tissue.norm();
  out.active_contacts = active;
  out.fem_step = fem_step;
  return out;
}

void spread_sphere_forces(std::span<const SphereForce> forces, const fem::SphereLinks& links,
                          std::span<double> nodal_forces_n) {
  for (const SphereForce& f : forces) {
    if (f.sphere_id >= links.size()) continue;
    const auto nodes = links.nodes(f.sphere_id);
    const auto weights = links.weights(f.sphere_id);
    for (std::size_t m = 0; m < nodes.size(); ++m) {
      for (std::size_t d = 0; d < 3; ++d) {
        nodal_forces_n[3 * std::size_t{nodes[m]} + d] +=
            weights[m] * f.force_n[static_cast<Eigen::Index>(d)];
      }
    }
  }
}

}  // namespace fahr::contact
