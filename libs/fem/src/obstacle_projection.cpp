// Nodes out of the static anatomy (see obstacle_projection.h).
#include "fahr/fem/obstacle_projection.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fahr::fem {
namespace {

constexpr double kUnsampled = -std::numeric_limits<double>::infinity();
// A field's normal shorter than this cannot be trusted as a direction (a
// point on a medial sheet of the obstacle); the node is left for the next
// pass, when it will have moved.
constexpr double kMinNormalLength = 0.5;
// Regula falsi iterations for a surface's entry point: the distance is
// nearly linear along a path of a few millimetres, and the push along the
// normal that follows removes what is left.
constexpr int kEntryIterations = 6;
// Sphere tracing of a node's path: a step is the sampled distance less the
// margin (no surface is nearer), at least this, m: 0.1 mm is far below an
// element and lets a path that grazes the margin end within kPathSteps.
constexpr double kMinPathStep = 1e-4;
// Beyond this many samples a path is left to the push along the normal.
constexpr int kPathSteps = 32;
// Samples of the trace that decides whether a node is going home (from its
// rest position, up to a few centimetres): beyond them it is undecided and
// the node is treated as not going home.
constexpr int kHomeTraceSteps = 256;

}  // namespace

ObstacleProjection::ObstacleProjection(std::span<const ObstacleField* const> fields,
                                       std::size_t node_count,
                                       const ObstacleProjectionSettings& settings)
    : fields_(fields.begin(), fields.end()),
      settings_(settings),
      clearance_m_(node_count * fields.size(), kUnsampled),
      sampled_at_m_(node_count, Eigen::Vector3d::Zero()),
      moved_(node_count, 0),
      move_normal_(node_count, Eigen::Vector3d::UnitZ()),
      beyond_(node_count * fields.size(), 0) {
  settings_.max_moves_per_node = std::max(1, settings_.max_moves_per_node);
  settings_.max_rounds = std::max(1, settings_.max_rounds);
}

void ObstacleProjection::begin_step() {
  std::fill(moved_.begin(), moved_.end(), std::uint8_t{0});
  nodes_moved_ = 0;
  nodes_returned_ = 0;
  nodes_beyond_ = 0;
  std::fill(beyond_.begin(), beyond_.end(), std::uint8_t{0});
}

bool ObstacleProjection::segment_enters(const ObstacleField& field, const Eigen::Vector3d& a,
                                        const Eigen::Vector3d& b, double level_m,
                                        bool if_undecided) const {
  const double length = (b - a).norm();
  const Eigen::Vector3d direction =
      length > 0.0 ? Eigen::Vector3d((b - a) / length) : Eigen::Vector3d::Zero();
  double t = 0.0;
  for (int i = 0; i < kHomeTraceSteps; ++i) {
    const double d = field.sample(a + std::min(t, length) * direction).distance_m;
    if (!std::isfinite(d)) return if_undecided;
    if (d < level_m) return true;
    if (t >= length) return false;
    t += std::max(d - level_m, kMinPathStep);
  }
  return if_undecided;
}

void ObstacleProjection::forget_clearances() {
  std::fill(clearance_m_.begin(), clearance_m_.end(), kUnsampled);
}

void ObstacleProjection::spend_clearance(std::size_t node, double distance_m) {
  double* clearance = clearance_m_.data() + node * fields_.size();
  for (std::size_t f = 0; f < fields_.size(); ++f) clearance[f] -= distance_m;
}

// Illinois regula falsi on g(t) = d(start + t (x - start)) - level, with
// g(0) >= 0 > g(1): keeps the bracket, halves a stale end's value.
Eigen::Vector3d ObstacleProjection::entry_point(const ObstacleField& field,
                                                const Eigen::Vector3d& start,
                                                double start_distance_m, const Eigen::Vector3d& x,
                                                double distance_m, double level_m) const {
  double t_out = 0.0, g_out = start_distance_m - level_m;
  double t_in = 1.0, g_in = distance_m - level_m;
  int stale_side = 0;
  for (int i = 0; i < kEntryIterations && g_out - g_in > settings_.tolerance_m; ++i) {
    const double t = t_out + (t_in - t_out) * g_out / (g_out - g_in);
    const double g = field.sample(start + t * (x - start)).distance_m - level_m;
    if (!std::isfinite(g)) break;
    if (g >= 0.0) {
      t_out = t;
      g_out = g;
      if (stale_side == -1) g_in *= 0.5;
      stale_side = -1;
    } else {
      t_in = t;
      g_in = g;
      if (stale_side == 1) g_out *= 0.5;
      stale_side = 1;
    }
  }
  return start + t_out * (x - start);  // the outside end: never in the obstacle
}

// Sphere tracing from the step's start toward x: the first point of the
// path closer than the margin, refined by regula falsi. x stays where it is
// when the path is clear, when it started within the margin (a node resting
// on the bone: the push along the normal decides) or when the path grazes
// the margin for longer than the trace follows it.
double ObstacleProjection::enter_along_path(const ObstacleField& field,
                                            const Eigen::Vector3d& start, Eigen::Vector3d& x,
                                            ObstacleSample& s, ProjectionReport& report) const {
  const double margin = settings_.margin_m;
  const double length = (x - start).norm();
  const double d0 = field.sample(start).distance_m;
  if (!(d0 >= margin - settings_.tolerance_m) || !(length > 0.0)) return 0.0;
  const Eigen::Vector3d direction = (x - start) / length;
  double t = 0.0, d = d0;
  for (int i = 0; i < kPathSteps; ++i) {
    const double t_next = t + std::max(d - margin, kMinPathStep);
    if (t_next >= length) return 0.0;
    const Eigen::Vector3d next = start + t_next * direction;
    const double d_next = field.sample(next).distance_m;
    if (!std::isfinite(d_next)) return 0.0;
    if (d_next < margin - settings_.tolerance_m) {
      report.obstacle_deepest_m = std::max(report.obstacle_deepest_m, -s.distance_m);
      const Eigen::Vector3d entry =
          entry_point(field, start + t * direction, d, next, d_next, margin);
      const Eigen::Vector3d end = x;
      x = entry;
      s = field.sample(x);
      return (end - x).norm();
    }
    t = t_next;
    d = d_next;
  }
  return 0.0;
}

// Against each obstacle in turn: sample unless the clearance proves the node
// is out, then move it out along the normal until it sits at the margin.
// A move out of one obstacle may take a node toward another sampled before;
// the clearances record it and the next round's pass catches it.
ObstacleProjection::NodeOutcome ObstacleProjection::project_node(std::size_t node,
                                                                 const Eigen::Vector3d* start,
                                                                 const Eigen::Vector3d* rest,
                                                                 Eigen::Vector3d& x,
                                                                 ProjectionReport& report) {
  const double margin = settings_.margin_m;
  spend_clearance(node, (x - sampled_at_m_[node]).norm());
  sampled_at_m_[node] = x;
  double* clearance = clearance_m_.data() + node * fields_.size();
  bool moved = false;
  bool unresolved = false;
  for (std::size_t f = 0; f < fields_.size(); ++f) {
    if (clearance[f] >= margin) continue;
    if (rest != nullptr) {
      // Once a step, and only for nodes near the obstacle: beyond it?
      std::uint8_t& beyond = beyond_[node * fields_.size() + f];
      if (beyond == 0) {
        // A node within beyond_depth_m of its rest position cannot be that
        // deep along the segment (the distance is 1-Lipschitz), and a node
        // whose rest is inside the obstacle has no side to be beyond.
        const Eigen::Vector3d& from = start != nullptr ? *start : x;
        const bool far_from_rest = (from - *rest).norm() > settings_.beyond_depth_m;
        beyond = far_from_rest && fields_[f]->sample(*rest).distance_m >= 0.0 &&
                         segment_enters(*fields_[f], *rest, from, -settings_.beyond_depth_m, false)
                     ? 2
                     : 1;
        if (beyond == 2) ++nodes_beyond_;
      }
      if (beyond == 2) continue;
    }
    const Eigen::Vector3d before = x;
    ObstacleSample s = fields_[f]->sample(x);
    if (start != nullptr && s.distance_m - (x - *start).norm() < margin) {
      // The path from the step's start comes closer to this obstacle than
      // the margin somewhere, or may have: follow it from the start.
      const Eigen::Vector3d end = x;
      const ObstacleSample end_sample = s;
      double back = enter_along_path(*fields_[f], *start, x, s, report);
      if (back > 0.0 && rest != nullptr && s.distance_m >= 0.0 && end_sample.distance_m >= 0.0 &&
          !segment_enters(*fields_[f], *rest, end, 0.0, true) &&
          segment_enters(*fields_[f], *rest, *start, 0.0, false)) {
        // Beyond the bone and going home through it: let it.
        x = end;
        s = end_sample;
        back = 0.0;
        ++nodes_returned_;
      }
      if (back > 0.0) {
        spend_clearance(node, back);
        moved = true;
      }
    }
    for (int move = 0;
         move < settings_.max_moves_per_node && s.distance_m < margin - settings_.tolerance_m;
         ++move) {
      const double length = s.normal.norm();
      if (!(length > kMinNormalLength) || !s.normal.allFinite()) break;
      report.obstacle_deepest_m = std::max(report.obstacle_deepest_m, -s.distance_m);
      const Eigen::Vector3d step = (margin - s.distance_m) / length * s.normal;
      x += step;
      spend_clearance(node, step.norm());
      moved = true;
      s = fields_[f]->sample(x);
    }
    if (!std::isfinite(s.distance_m)) return NodeOutcome::kNonFinite;
    const double normal_length = s.normal.norm();
    if (x != before && normal_length > kMinNormalLength && s.normal.allFinite()) {
      move_normal_[node] = s.normal / normal_length;
    }
    clearance[f] = s.distance_m;
    sampled_at_m_[node] = x;
    unresolved = unresolved || s.distance_m < margin - settings_.tolerance_m;
  }
  if (unresolved) return NodeOutcome::kUnresolved;
  return moved ? NodeOutcome::kMoved : NodeOutcome::kClear;
}

int ObstacleProjection::project(std::span<double> positions_m,
                                std::span<const double> inverse_mass_per_node,
                                ProjectionReport& report, std::span<const double> start_positions_m,
                                std::span<const double> rest_positions_m) {
  if (fields_.empty()) return 0;
  int moved_now = 0;
  report.obstacle_unresolved = 0;
  report.obstacle_non_finite = 0;
  const std::size_t nodes = std::min(moved_.size(), inverse_mass_per_node.size());
  for (std::size_t n = 0; n < nodes; ++n) {
    if (!(inverse_mass_per_node[n] > 0.0)) continue;  // fixed: never moves
    const Eigen::Map<Eigen::Vector3d> stored(positions_m.data() + 3 * n);
    if (!stored.allFinite()) {
      ++report.obstacle_non_finite;
      continue;
    }
    Eigen::Vector3d x = stored;
    Eigen::Vector3d start;
    const bool have_start = start_positions_m.size() >= 3 * (n + 1);
    if (have_start) start = Eigen::Map<const Eigen::Vector3d>(start_positions_m.data() + 3 * n);
    const bool start_usable = have_start && start.allFinite();
    const bool have_rest = rest_positions_m.size() >= 3 * (n + 1);
    Eigen::Vector3d rest = Eigen::Vector3d::Zero();
    if (have_rest) rest = Eigen::Map<const Eigen::Vector3d>(rest_positions_m.data() + 3 * n);
    const NodeOutcome outcome =
        project_node(n, start_usable ? &start : nullptr, have_rest ? &rest : nullptr, x, report);
    if (outcome == NodeOutcome::kNonFinite || !x.allFinite()) {
      // Leave the node where the step put it and sample it afresh next time.
      std::fill_n(clearance_m_.data() + n * fields_.size(), fields_.size(), kUnsampled);
      ++report.obstacle_non_finite;
      continue;
    }
    if (outcome == NodeOutcome::kUnresolved) ++report.obstacle_unresolved;
    if (x == Eigen::Vector3d(stored)) continue;
    Eigen::Map<Eigen::Vector3d>(positions_m.data() + 3 * n) = x;
    ++moved_now;
    if (moved_[n] == 0) {
      moved_[n] = 1;
      ++nodes_moved_;
    }
  }
  report.obstacle_nodes = nodes_moved_;
  return moved_now;
}

}  // namespace fahr::fem
