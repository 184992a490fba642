// Validation of FillSettings: the first tier (setup), with messages that name
// the field and its range.
#include "fahr/sphere_layout/fill_settings.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace fahr::sphere_layout {
namespace {

void require(bool ok, const char* field, double value, const char* range) {
  if (ok) return;
  std::ostringstream message;
  message << "sphere fill settings: " << field << " = " << value << " is out of range, expected "
          << range;
  throw std::invalid_argument(message.str());
}

}  // namespace

void validate_fill_settings(const FillSettings& s) {
  require(std::isfinite(s.volume_ratio) && s.volume_ratio >= 0.5 && s.volume_ratio <= 1000.0,
          "volume_ratio", s.volume_ratio, "[0.5, 1000]");
  require(s.refinement_levels >= 0 && s.refinement_levels <= 6, "refinement_levels",
          s.refinement_levels, "[0, 6]");
  require(s.max_linked_tets >= 1 && s.max_linked_tets <= 64, "max_linked_tets", s.max_linked_tets,
          "[1, 64]");
  require(std::isfinite(s.weight_spread) && s.weight_spread >= 0.0 && s.weight_spread < 1.0,
          "weight_spread", s.weight_spread, "[0, 1)");
  require(std::isfinite(s.hugging_weight_spread) && s.hugging_weight_spread >= 0.0 &&
              s.hugging_weight_spread < 1.0,
          "hugging_weight_spread", s.hugging_weight_spread, "[0, 1)");
  require(std::isfinite(s.hugging_anchor_depth_factor) && s.hugging_anchor_depth_factor >= 1.0 &&
              s.hugging_anchor_depth_factor <= 8.0,
          "hugging_anchor_depth_factor", s.hugging_anchor_depth_factor, "[1, 8]");
  require(s.anchor_gap_m >= 0.0, "anchor_gap_m", s.anchor_gap_m,
          ">= 0 (m) or +infinity");  // NaN fails
  require(std::isfinite(s.min_radius_fraction) && s.min_radius_fraction >= 0.0 &&
              s.min_radius_fraction <= 1.0,
          "min_radius_fraction", s.min_radius_fraction, "[0, 1]");
  require(std::isfinite(s.hugging_tolerance_m) && s.hugging_tolerance_m > 0.0,
          "hugging_tolerance_m", s.hugging_tolerance_m, "> 0 (m)");
  require(std::isfinite(s.hugging_sample_spacing_m) && s.hugging_sample_spacing_m > 0.0,
          "hugging_sample_spacing_m", s.hugging_sample_spacing_m, "> 0 (m)");
  require(std::isfinite(s.hugging_radius_fraction) && s.hugging_radius_fraction > 0.0 &&
              s.hugging_radius_fraction <= 4.0,
          "hugging_radius_fraction", s.hugging_radius_fraction, "(0, 4]");
  require(s.hugging_rounds >= 0 && s.hugging_rounds <= 8, "hugging_rounds", s.hugging_rounds,
          "[0, 8]");
  require(s.max_spheres >= 1, "max_spheres", static_cast<double>(s.max_spheres), ">= 1");
}

}  // namespace fahr::sphere_layout
