#include "fahr/fem/volume_floor.h"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>

namespace fahr::fem {

namespace {

Eigen::Vector3d node(std::span<const double> x, std::uint32_t n) {
  return {x[3 * std::size_t{n}], x[3 * std::size_t{n} + 1], x[3 * std::size_t{n} + 2]};
}

}  // namespace

double signed_volume(std::span<const double> positions_m, const Tet& t) {
  const Eigen::Vector3d x0 = node(positions_m, t[0]);
  return (node(positions_m, t[1]) - x0)
             .dot((node(positions_m, t[2]) - x0).cross(node(positions_m, t[3]) - x0)) /
         6.0;
}

VolumeFloor::VolumeFloor(const ElementRest& rest, const VolumeFloorSettings& settings)
    : rest_(rest), settings_(settings), floor_m3_(rest.size()), unchecked_(rest.size(), 1) {
  for (std::size_t e = 0; e < rest.size(); ++e) floor_m3_[e] = settings.ratio * rest.volume_m3[e];
  below_.reserve(rest.size());
  std::uint32_t nodes = 0;
  for (const Tet& tet : rest.tets) {
    for (const std::uint32_t n : tet) nodes = std::max(nodes, n + 1);
  }
  node_start_.assign(std::size_t{nodes} + 1, 0);
  for (const Tet& tet : rest.tets) {
    for (const std::uint32_t n : tet) ++node_start_[std::size_t{n} + 1];
  }
  for (std::size_t n = 0; n < nodes; ++n) node_start_[n + 1] += node_start_[n];
  moved_.assign(rest.size(), 0);
  direction_.resize(rest.size());
  moved_tets_.reserve(rest.size());
  node_tets_.resize(node_start_.back());
  std::vector<std::uint32_t> fill(node_start_.begin(), node_start_.end() - 1);
  for (std::size_t e = 0; e < rest.size(); ++e) {
    for (const std::uint32_t n : rest.tets[e])
      node_tets_[fill[n]++] = static_cast<std::uint32_t>(e);
  }
}

void VolumeFloor::begin_step() {
  for (const std::uint32_t e : moved_tets_) moved_[e] = 0;
  moved_tets_.clear();
}

void VolumeFloor::mark_around(std::uint32_t node) {
  for (std::uint32_t k = node_start_[node]; k < node_start_[std::size_t{node} + 1]; ++k)
    unchecked_[node_tets_[k]] = 1;
}

void VolumeFloor::note_moves(std::span<const double> positions_m) {
  const std::size_t nodes = node_start_.size() - 1;
  if (last_positions_.size() != positions_m.size() || positions_m.size() < 3 * nodes) {
    std::fill(unchecked_.begin(), unchecked_.end(), std::uint8_t{1});
    return;
  }
  for (std::size_t n = 0; n < nodes; ++n) {
    const double* now = positions_m.data() + 3 * n;
    const double* then = last_positions_.data() + 3 * n;
    // != rather than a tolerance: any change, NaN included, is a move.
    if (now[0] != then[0] || now[1] != then[1] || now[2] != then[2])
      mark_around(static_cast<std::uint32_t>(n));
  }
}

bool VolumeFloor::open(std::size_t e, std::span<double> positions_m,
                       std::span<const double> inverse_mass_per_kg) {
  const Tet& tet = rest_.tets[e];
  const double volume = signed_volume(positions_m, tet);
  // Written so that a NaN volume is left alone: the step's divergence
  // check, not this pass, deals with non-finite positions.
  if (!(volume < kVolumeFloorSlack * floor_m3_[e])) return false;
  const Eigen::Vector3d x0 = node(positions_m, tet[0]);
  const Eigen::Vector3d d1 = node(positions_m, tet[1]) - x0;
  const Eigen::Vector3d d2 = node(positions_m, tet[2]) - x0;
  const Eigen::Vector3d d3 = node(positions_m, tet[3]) - x0;
  std::array<Eigen::Vector3d, 4> gradient;
  gradient[1] = d2.cross(d3) / 6.0;
  gradient[2] = d3.cross(d1) / 6.0;
  gradient[3] = d1.cross(d2) / 6.0;
  gradient[0] = -(gradient[1] + gradient[2] + gradient[3]);
  double weight = 0.0;
  for (int a = 0; a < 4; ++a) weight += inverse_mass_per_kg[tet[a]] * gradient[a].squaredNorm();
  // A tet collapsed to a line or a point has no direction to open in, and
  // one with only fixed nodes cannot move; its neighbours' moves may open
  // it in a later sweep.
  if (!(weight > 0.0) || !std::isfinite(weight)) return true;
  const double scale = (floor_m3_[e] - volume) / weight;
  std::array<Eigen::Vector3d, 4>& direction = direction_[e];
  double length_squared = 0.0;
  for (int a = 0; a < 4; ++a) {
    const double w = inverse_mass_per_kg[tet[a]];
    direction[a] = w == 0.0 ? Eigen::Vector3d::Zero() : gradient[a];
    length_squared += direction[a].squaredNorm();
    if (w == 0.0) continue;
    const Eigen::Vector3d move = scale * w * gradient[a];
    for (int d = 0; d < 3; ++d) positions_m[3 * std::size_t{tet[a]} + d] += move[d];
    mark_around(tet[a]);
  }
  // weight > 0, so some free node has a non-zero gradient.
  const double length = std::sqrt(length_squared);
  for (Eigen::Vector3d& part : direction) part /= length;
  if (moved_[e] == 0) moved_tets_.push_back(static_cast<std::uint32_t>(e));
  moved_[e] = 1;
  return true;
}

VolumeFloorReport VolumeFloor::project(std::span<double> positions_m,
                                       std::span<const double> inverse_mass_per_kg) {
  VolumeFloorReport report;
  if (settings_.ratio <= 0.0) return report;
  note_moves(positions_m);
  const auto remember = [&] { last_positions_.assign(positions_m.begin(), positions_m.end()); };
  for (int sweep = 0; sweep < settings_.max_sweeps; ++sweep) {
    below_.clear();
    for (std::size_t e = 0; e < rest_.size(); ++e) {
      if (unchecked_[e] == 0) continue;  // above its floor, and none of its nodes moved since
      unchecked_[e] = 0;
      if (open(e, positions_m, inverse_mass_per_kg)) below_.push_back(e);
    }
    if (sweep == 0) report.below = static_cast<int>(below_.size());
    report.sweeps = sweep + 1;
    if (below_.empty()) {
      remember();
      return report;
    }
    // Coupled tets (sharing nodes) settle over several sweeps; only the
    // ones found below can still be, until their moves push a neighbour
    // under, which the next full sweep finds.
    for (int inner = 0; inner < settings_.inner_sweeps; ++inner) {
      bool any = false;
      for (const std::size_t e : below_) any = open(e, positions_m, inverse_mass_per_kg) || any;
      if (!any) break;
    }
  }
  // A count without moves, for the report; the tets still below stay
  // unchecked for the next pass.
  for (std::size_t e = 0; e < rest_.size(); ++e) {
    if (!(signed_volume(positions_m, rest_.tets[e]) >= kVolumeFloorSlack * floor_m3_[e])) {
      unchecked_[e] = 1;
      if (signed_volume(positions_m, rest_.tets[e]) < kVolumeFloorSlack * floor_m3_[e])
        ++report.unresolved;
    }
  }
  remember();
  return report;
}

}  // namespace fahr::fem
