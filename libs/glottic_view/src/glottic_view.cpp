// GlotticView: sunflower samples on the opening, lines of sight through the
// occluders' bounding-volume trees.
#include "fahr/glottic_view/glottic_view.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace fahr::glottic_view {
namespace {

// Vogel's sunflower on the unit disc: sample i at radius sqrt((i + 1/2) / n),
// turned by the golden angle each step; every sample stands for an equal
// area. opening_point's map is linear, so they stay equal-area on the ellipse.
std::vector<Eigen::Vector3d> sunflower(const Opening& o, std::size_t n) {
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  std::vector<Eigen::Vector3d> points(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double r = std::sqrt((static_cast<double>(i) + 0.5) / static_cast<double>(n));
    const double a = golden * static_cast<double>(i);
    points[i] = opening_point(o, r * std::cos(a), r * std::sin(a));
  }
  return points;
}

}  // namespace

Eigen::Vector3d opening_point(const Opening& o, double x, double y) {
  const bool ellipse = o.minor_radius_m > 0.0;
  const Eigen::Vector3d u = ellipse ? o.major_axis : o.normal.unitOrthogonal();
  const Eigen::Vector3d v = o.normal.cross(u);
  return o.centre_m + o.radius_m * x * u + (ellipse ? o.minor_radius_m : o.radius_m) * y * v;
}

GlotticView::GlotticView(const Opening& opening, std::size_t samples) : opening_(opening) {
  if (!(opening.radius_m > 0.0) || !std::isfinite(opening.radius_m)) {
    throw std::invalid_argument("glottic view: the opening's radius must be positive");
  }
  const double length = opening.normal.norm();
  if (!(length > 1e-12) || !std::isfinite(length) || !opening.centre_m.allFinite()) {
    throw std::invalid_argument("glottic view: the opening needs a finite centre and a normal");
  }
  if (samples < 16) {
    throw std::invalid_argument("glottic view: at least 16 samples");
  }
  opening_.normal /= length;
  if (opening.minor_radius_m != 0.0) {
    if (!(opening.minor_radius_m > 0.0) || !(opening.minor_radius_m <= opening.radius_m)) {
      throw std::invalid_argument(
          "glottic view: the opening's minor radius must lie in (0, radius]");
    }
    Eigen::Vector3d u =
        opening.major_axis - opening.major_axis.dot(opening_.normal) * opening_.normal;
    if (!u.allFinite() || !(u.norm() > 1e-6)) {
      throw std::invalid_argument(
          "glottic view: an elliptic opening needs a major axis in its plane");
    }
    u.normalize();
    opening_.major_axis = u;
  }
  points_ = sunflower(opening_, samples);
}

void GlotticView::add_rigid(const geometry::SurfaceMesh& surface_world) {
  rigid_.emplace_back(surface_world);
}

void GlotticView::set_tool(const geometry::SurfaceMesh& surface_tool_frame) {
  tool_.emplace(surface_tool_frame);
}

std::size_t GlotticView::add_deformable(std::vector<geometry::Triangle> boundary) {
  for (const auto& t : boundary) {
    for (const auto i : t) {
      if (i < 0) throw std::invalid_argument("glottic view: a negative node index");
    }
  }
  deformable_boundaries_.push_back(std::move(boundary));
  return deformable_boundaries_.size() - 1;
}

ViewScore GlotticView::score(
    const Eigen::Vector3d& eye_world, const std::optional<Eigen::Isometry3d>& world_from_tool,
    std::span<const std::span<const Eigen::Vector3d>> deformable_positions) {
  if (!eye_world.allFinite()) {
    throw std::invalid_argument("glottic view: the eye is not finite");
  }
  std::vector<geometry::TriangleBvh> soft;
  soft.reserve(deformable_positions.size());
  for (std::size_t b = 0; b < deformable_positions.size() && b < deformable_boundaries_.size();
       ++b) {
    const auto& positions = deformable_positions[b];
    for (const auto& p : positions) {
      if (!p.allFinite()) {
        throw std::invalid_argument("glottic view: deformable body " + std::to_string(b) +
                                    " has a non-finite node");
      }
    }
    try {
      soft.emplace_back(positions, deformable_boundaries_[b]);
    } catch (const std::out_of_range& e) {
      throw std::invalid_argument("glottic view: deformable body " + std::to_string(b) + ": " +
                                  e.what());
    }
  }
  const Eigen::Isometry3d tool_from_world =
      world_from_tool ? world_from_tool->inverse() : Eigen::Isometry3d::Identity();
  const Eigen::Vector3d eye_tool = tool_from_world * eye_world;

  ViewScore out;
  out.facing = (eye_world - opening_.centre_m).dot(opening_.normal) > 0.0;
  double total = 0.0;
  double seen = 0.0;
  for (const Eigen::Vector3d& p : points_) {
    const Eigen::Vector3d sight = eye_world - p;
    const double d2 = sight.squaredNorm();
    const double cosine = sight.dot(opening_.normal) / std::sqrt(d2);
    if (!(cosine > 0.0)) continue;
    const double weight = cosine / d2;
    ++out.samples;
    total += weight;
    bool blocked = false;
    for (const auto& tree : rigid_) {
      if (tree.segment_hits(eye_world, p)) {
        blocked = true;
        break;
      }
    }
    for (std::size_t b = 0; !blocked && b < soft.size(); ++b) {
      blocked = soft[b].segment_hits(eye_world, p);
    }
    if (!blocked && tool_ && world_from_tool) {
      blocked = tool_->segment_hits(eye_tool, tool_from_world * p);
    }
    if (!blocked) {
      ++out.visible;
      seen += weight;
    }
  }
  out.visible_share = total > 0.0 ? seen / total : 0.0;
  return out;
}

}  // namespace fahr::glottic_view
