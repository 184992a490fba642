// Swept blade: an L section along a path (curved tip, straight spatula,
// bend at the heel, straight handle), capped by rounded ends.
#include "fahr/scenegen/laryngoscope_blade.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "fahr/scenegen/param_surfaces.h"
#include "fahr/scenegen/piecewise_linear.h"

namespace fahr::scenegen {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kPathStepMm = 0.05;  // integration step of the centre-line
constexpr double kTipCapMm = 0.8;     // rounded distal end
constexpr double kHandleCapMm = 4.0;  // rounded end of the handle
constexpr int kCapStations = 6;
// Points per side of the L section, fixed so every station has the same count.
constexpr std::array<int, 6> kSidePoints = {20, 2, 16, 10, 2, 14};

struct Path {
  std::vector<Eigen::Vector2d> points;  // every kPathStepMm, from the tip
  std::vector<double> angles;           // tangent angle from +x, rad
  Eigen::Vector2d point(double s) const {
    const double f = std::clamp(s / kPathStepMm, 0.0, static_cast<double>(points.size() - 1));
    const size_t i = std::min(static_cast<size_t>(f), points.size() - 2);
    const double t = f - static_cast<double>(i);
    return (1.0 - t) * points[i] + t * points[i + 1];
  }
  double angle(double s) const {
    const double f = std::clamp(s / kPathStepMm, 0.0, static_cast<double>(angles.size() - 1));
    const size_t i = std::min(static_cast<size_t>(f), angles.size() - 2);
    const double t = f - static_cast<double>(i);
    return (1.0 - t) * angles[i] + t * angles[i + 1];
  }
};

double tangent_angle(const BladeParameters& p, double s) {
  const double tip_curve = p.tip_curve_deg * kPi / 180.0;
  if (s < p.tip_curve_length_mm) {
    const double r = 1.0 - s / p.tip_curve_length_mm;
    return -tip_curve * r * r;  // heading down from the raised tip, easing to level
  }
  if (s < p.length_mm) return 0.0;
  const double bend = p.heel_bend_radius_mm * 0.5 * kPi;
  if (s < p.length_mm + bend) return -(s - p.length_mm) / p.heel_bend_radius_mm;
  return -0.5 * kPi;
}

Path make_path(const BladeParameters& p, double total) {
  Path path;
  const int steps = static_cast<int>(std::ceil(total / kPathStepMm));
  Eigen::Vector2d x(0.0, 0.0);
  for (int i = 0; i <= steps; ++i) {
    const double s = i * kPathStepMm;
    path.points.push_back(x);
    path.angles.push_back(tangent_angle(p, s));
    const double mid = tangent_angle(p, s + 0.5 * kPathStepMm);  // midpoint rule
    x += kPathStepMm * Eigen::Vector2d(std::cos(mid), std::sin(mid));
  }
  return path;
}

// L section at width w, web height h: corners counter-clockwise in (z, n),
// n = 0 the underside, starting at the web's lower outer corner.
std::vector<Eigen::Vector2d> l_section(const BladeParameters& p, double w, double h) {
  const double t = p.plate_thickness_mm;
  const double tw = p.web_thickness_mm;
  const std::array<Eigen::Vector2d, 6> corners = {
      Eigen::Vector2d(-0.5 * w, 0.0),    Eigen::Vector2d(0.5 * w, 0.0),
      Eigen::Vector2d(0.5 * w, t),       Eigen::Vector2d(-0.5 * w + tw, t),
      Eigen::Vector2d(-0.5 * w + tw, h), Eigen::Vector2d(-0.5 * w, h)};
  std::vector<Eigen::Vector2d> points;
  for (size_t side = 0; side < corners.size(); ++side) {
    const Eigen::Vector2d& a = corners[side];
    const Eigen::Vector2d& b = corners[(side + 1) % corners.size()];
    for (int k = 0; k < kSidePoints[side]; ++k) {
      points.push_back(a + (b - a) * (static_cast<double>(k) / kSidePoints[side]));
    }
  }
  return points;
}

// Distance from an interior point c along unit direction d to a circle.
double ray_to_circle(const Eigen::Vector2d& c, const Eigen::Vector2d& d,
                     const Eigen::Vector2d& centre, double radius) {
  const Eigen::Vector2d m = c - centre;
  const double b = m.dot(d);
  const double q = m.squaredNorm() - radius * radius;  // negative: c is inside
  return -b + std::sqrt(b * b - q);
}

}  // namespace

TriangleMesh make_miller_blade(const BladeParameters& p, double resolution_mm) {
  const double bend = p.heel_bend_radius_mm * 0.5 * kPi;
  const double total = p.length_mm + bend + p.handle_length_mm;
  const Path path = make_path(p, total);
  const int body_stations = std::max(8, static_cast<int>(std::ceil(total / resolution_mm)));
  const int n_along = body_stations + 2 * kCapStations;
  int section_points = 0;
  for (const int n : kSidePoints) section_points += n;

  // The handle: a circle whose centre sits over the web, so the kernel point
  // of the L (inside plate and web) is inside it and the morph stays star-shaped.
  const double handle_radius = 0.5 * p.handle_diameter_mm;
  const auto kernel = [&p](double w) {
    return Eigen::Vector2d(-0.5 * w + 0.5 * p.web_thickness_mm, 0.5 * p.plate_thickness_mm);
  };
  const auto section = [&](double s, double cap_scale, int j) -> Vec3 {
    const double q = std::clamp(s / p.length_mm, 0.0, 1.0);
    const double w = p.tip_width_mm + (p.heel_width_mm - p.tip_width_mm) * q;
    const double h = p.tip_web_height_mm + (p.heel_web_height_mm - p.tip_web_height_mm) * q;
    const double morph = smoothstep(p.length_mm, p.length_mm + bend, s);
    const Eigen::Vector2d c = kernel(w);
    const Eigen::Vector2d handle_centre(c.x(), 0.9 * handle_radius);
    const Eigen::Vector2d blade_point = l_section(p, w, h)[static_cast<size_t>(j)];
    const Eigen::Vector2d dir = (blade_point - c).normalized();
    const double radius = (1.0 - morph) * (blade_point - c).norm() +
                          morph * ray_to_circle(c, dir, handle_centre, handle_radius);
    // Caps shrink towards the kernel at the tip and the handle centre at the end.
    const Eigen::Vector2d cap_centre = c + morph * (handle_centre - c);
    const Eigen::Vector2d zn = cap_centre + cap_scale * (c + radius * dir - cap_centre);
    const double sc = std::clamp(s, 0.0, total);
    const double angle = path.angle(sc);
    const Eigen::Vector2d tangent(std::cos(angle), std::sin(angle));
    const Eigen::Vector2d normal(-std::sin(angle), std::cos(angle));
    const Eigen::Vector2d xy = path.point(sc) + (s - sc) * tangent + zn.y() * normal;
    return Vec3(xy.x(), xy.y(), zn.x());
  };
  const auto map = [&](double along, double around) {
    const int i = static_cast<int>(std::lround(along * n_along));
    const int j = static_cast<int>(std::lround(around * section_points)) % section_points;
    if (i <= kCapStations) {  // tip cap: quarter circle from the pole to full size
      const double psi = 0.5 * kPi * i / kCapStations;
      return section(-kTipCapMm * std::cos(psi), std::sin(psi), j);
    }
    if (i >= n_along - kCapStations) {
      const double psi = 0.5 * kPi * (n_along - i) / kCapStations;
      return section(total + kHandleCapMm * std::cos(psi), std::sin(psi), j);
    }
    const double s = total * (i - kCapStations) / static_cast<double>(body_stations);
    return section(s, 1.0, j);
  };
  return make_param_sphere(map, n_along, section_points);
}

}  // namespace fahr::scenegen
