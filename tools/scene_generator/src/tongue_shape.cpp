// Implicit tongue: see tongue_shape.h for the construction.
#include "fahr/scenegen/tongue_shape.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fahr/scenegen/piecewise_linear.h"

namespace fahr::scenegen {
namespace {

// Mid-line as a cubic Bezier through the tip, relative to the tip, for a
// 40 mm tongue: forward part nearly level under the palate, the back third
// turning down towards the vallecula. Scaled to the requested length.
const Eigen::Vector2d kSpineControl[4] = {{0.0, 0.0}, {-15.0, 2.5}, {-28.0, 2.5}, {-33.0, -11.0}};
constexpr int kSpineSamples = 400;

// Section profiles along the mid-line, as fractions of the named dimensions
// (tip narrow and thin, widest and deepest over the back half).
const PiecewiseLinear kDorsalProfile{{0.0, 0.45}, {0.3, 0.95}, {0.6, 1.0}, {1.0, 1.05}};
const PiecewiseLinear kVentralProfile{{0.0, 0.3}, {0.25, 0.8}, {0.5, 1.0}, {1.0, 0.9}};
const PiecewiseLinear kWidthProfile{{0.0, 0.5}, {0.3, 0.8}, {0.7, 1.0}, {1.0, 1.0}};
constexpr double kTipCapOfHalfWidth = 0.6;  // rounded tip: cap length / tip half width

Eigen::Vector2d bezier(const Eigen::Vector2d* c, double t) {
  const double s = 1.0 - t;
  return s * s * s * c[0] + 3.0 * s * s * t * c[1] + 3.0 * s * t * t * c[2] + t * t * t * c[3];
}

}  // namespace

TongueShape::TongueShape(const TongueParameters& params) : params_(params) {
  std::vector<Eigen::Vector2d> raw;
  double raw_length = 0.0;
  for (int i = 0; i <= kSpineSamples; ++i) {
    raw.push_back(bezier(kSpineControl, static_cast<double>(i) / kSpineSamples));
    if (i > 0) raw_length += (raw[raw.size() - 1] - raw[raw.size() - 2]).norm();
  }
  const double scale = params.length_mm / raw_length;
  const Eigen::Vector2d tip(params.tip_x_mm, params.tip_y_mm);
  double arc = 0.0;
  for (size_t i = 0; i < raw.size(); ++i) {
    const Eigen::Vector2d p = tip + scale * raw[i];
    if (i > 0) arc += (p - spine_.back().point).norm();
    spine_.push_back({p, Eigen::Vector2d::Zero(), arc});
  }
  length_ = arc;
  for (size_t i = 0; i < spine_.size(); ++i) {
    const size_t a = i == 0 ? 0 : i - 1;
    const size_t b = std::min(i + 1, spine_.size() - 1);
    spine_[i].tangent = (spine_[b].point - spine_[a].point).normalized();
  }
  tip_cap_mm_ = kTipCapOfHalfWidth * section_at(0.0).half_width_mm;
  base_cap_mm_ = section_at(length_).ventral_mm;

  double reach = 0.0;
  for (const double s : {0.0, 0.5 * length_, length_}) {
    const Section sec = section_at(s);
    reach = std::max({reach, sec.dorsal_mm, sec.ventral_mm, sec.half_width_mm});
  }
  reach = std::max({reach, tip_cap_mm_, base_cap_mm_});
  lower_ = Vec3::Constant(std::numeric_limits<double>::infinity());
  upper_ = -lower_;
  for (const auto& s : spine_) {
    lower_ = lower_.cwiseMin(Vec3(s.point.x(), s.point.y(), 0.0));
    upper_ = upper_.cwiseMax(Vec3(s.point.x(), s.point.y(), 0.0));
  }
  lower_ -= Vec3::Constant(reach);
  upper_ += Vec3::Constant(reach);
}

TongueShape::Section TongueShape::section_at(double arc_mm) const {
  const double t = std::clamp(arc_mm / params_.length_mm, 0.0, 1.0);
  return {params_.dorsum_height_mm * kDorsalProfile(t),
          params_.ventral_depth_mm * kVentralProfile(t), 0.5 * params_.width_mm * kWidthProfile(t)};
}

double TongueShape::sweep_value(const Vec3& p) const {
  // Closest mid-line point (segment-exact), then ellipsoidal coordinates in
  // the local frame: axial beyond the ends, dorsal-ventral, lateral.
  const Eigen::Vector2d q(p.x(), p.y());
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector2d foot = spine_.front().point;
  double foot_arc = 0.0;
  double foot_t = 0.0;
  size_t foot_segment = 0;
  for (size_t i = 0; i + 1 < spine_.size(); ++i) {
    const Eigen::Vector2d a = spine_[i].point;
    const Eigen::Vector2d ab = spine_[i + 1].point - a;
    const double t = std::clamp((q - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    const Eigen::Vector2d c = a + t * ab;
    const double d = (q - c).squaredNorm();
    if (d < best) {
      best = d;
      foot = c;
      foot_arc = spine_[i].arc_mm + t * (spine_[i + 1].arc_mm - spine_[i].arc_mm);
      foot_t = t;
      foot_segment = i;
    }
  }
  // Blend the sample tangents so the local frame turns smoothly along the mid-line.
  const Eigen::Vector2d tangent =
      ((1.0 - foot_t) * spine_[foot_segment].tangent + foot_t * spine_[foot_segment + 1].tangent)
          .normalized();
  const Eigen::Vector2d dorsal(tangent.y(), -tangent.x());  // tangent turned towards the palate
  const Eigen::Vector2d rel = q - foot;
  const double axial = rel.dot(tangent);
  const double across = rel.dot(dorsal);
  const Section sec = section_at(foot_arc);
  double axial_term = 0.0;
  if (foot_arc <= 0.0 && axial < 0.0) axial_term = axial / tip_cap_mm_;
  if (foot_arc >= length_ && axial > 0.0) axial_term = axial / base_cap_mm_;
  const double vertical = across / (across >= 0.0 ? sec.dorsal_mm : sec.ventral_mm);
  const double lateral = p.z() / sec.half_width_mm;
  const double g = std::sqrt(axial_term * axial_term + vertical * vertical + lateral * lateral);
  // Scale the normalised radius to millimetres with a size that is continuous in arc.
  const double size = 0.25 * (sec.dorsal_mm + sec.ventral_mm + 2.0 * sec.half_width_mm);
  return (g - 1.0) * size;
}

double attachment_plane_y(const TongueParameters& params, double x_mm) {
  constexpr double kReferenceX = -15.0;  // x at which floor_y_at_x15_mm is given
  return params.floor_y_at_x15_mm + params.floor_slope * (x_mm - kReferenceX);
}

double TongueShape::attachment_plane_distance(const Vec3& p) const {
  return (attachment_plane_y(params_, p.x()) - p.y()) /
         std::sqrt(1.0 + params_.floor_slope * params_.floor_slope);
}

double TongueShape::value(const Vec3& p) const {
  return std::max(sweep_value(p), attachment_plane_distance(p));
}

}  // namespace fahr::scenegen
