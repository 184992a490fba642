// Gauss-Seidel position projection of sphere constraints (Algorithm 1).
#include "fahr/fem/projection.h"

#include <algorithm>

namespace fahr::fem {
namespace {

// Normals are unit vectors by contract; one shorter than this cannot be
// normalised reliably (c == q at the haptic side) and is skipped.
constexpr double kMinNormalLength = 1e-9;

}  // namespace

bool contact_is_frozen(const Contact& contact) {
  return contact.kind == ContactKind::kTool && contact.state == ContactState::kFrozen;
}

bool contact_is_projected(const Contact& contact) {
  return contact.state != ContactState::kCandidate && contact.kind != ContactKind::kForceOnly;
}

bool contact_is_projected(const Contact& contact, const ProjectionSettings& settings) {
  if (contact.kind == ContactKind::kObstacle && !settings.project_obstacle_contacts) return false;
  return contact_is_projected(contact);
}

bool move_sphere_centre(std::size_t sphere, const SphereLinks& links,
                        std::span<const double> inverse_mass_per_node, const Eigen::Vector3d& dc_m,
                        std::span<double> positions_m, Eigen::Vector3d* push_kg_m) {
  const auto nodes = links.nodes(sphere);
  const auto weights = links.weights(sphere);
  double denominator = 0.0;  // sum_j w_j^2 / m_j, 1/kg
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    denominator += weights[k] * weights[k] * inverse_mass_per_node[nodes[k]];
  }
  if (!(denominator > 0.0)) return false;
  const Eigen::Vector3d scaled = dc_m / denominator;
  if (push_kg_m != nullptr) *push_kg_m += scaled;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const double share = weights[k] * inverse_mass_per_node[nodes[k]];
    Eigen::Map<Eigen::Vector3d>(positions_m.data() + 3 * std::size_t{nodes[k]}) += share * scaled;
  }
  return true;
}

ProjectionReport project_contacts(const ContactSet& contacts, const SphereLinks& links,
                                  std::span<const double> inverse_mass_per_node,
                                  const ProjectionSettings& settings, std::span<double> positions_m,
                                  std::span<const double> step_start_m) {
  ProjectionReport report;
  for (const Contact& contact : contacts.contacts) {
    if (contact_is_projected(contact, settings)) ++report.constraints;
  }
  if (report.constraints == 0) return report;
  report.converged = false;
  for (int sweep = 0; sweep < settings.max_sweeps; ++sweep) {
    double largest = 0.0;
    report.unmovable = 0;
    report.degenerate_normals = 0;
    report.unknown_spheres = 0;
    for (const Contact& contact : contacts.contacts) {
      if (!contact_is_projected(contact, settings)) continue;
      if (contact.sphere_id >= links.size()) {
        ++report.unknown_spheres;
        continue;
      }
      const Eigen::Vector3d centre = links.centre(contact.sphere_id, positions_m.data());
      Eigen::Vector3d dc = Eigen::Vector3d::Zero();
      if (contact_is_frozen(contact)) {
        dc = links.centre(contact.sphere_id, step_start_m.data()) - centre;
      } else {
        const double length = contact.normal.norm();
        if (!(length > kMinNormalLength)) {
          ++report.degenerate_normals;
          continue;
        }
        const Eigen::Vector3d n = contact.normal / length;
        const double gap =
            (centre - contact.plane_point_m).dot(n) - links.radius_m(contact.sphere_id);
        if (gap >= 0.0) continue;  // inequality satisfied: no correction
        dc = -gap * n;
      }
      Eigen::Vector3d* push = contact.kind == ContactKind::kTool ? &report.tool_push_kg_m : nullptr;
      if (!move_sphere_centre(contact.sphere_id, links, inverse_mass_per_node, dc, positions_m,
                              push)) {
        ++report.unmovable;
        continue;
      }
      largest = std::max(largest, dc.norm());
    }
    ++report.sweeps;
    report.last_correction_m = largest;
    if (largest <= settings.tolerance_m) {
      report.converged = true;
      break;
    }
  }
  return report;
}

}  // namespace fahr::fem
