// First-order winding heat and the derated force limit (see the header).
#include "fahr/device/thermal_model.h"

#include <algorithm>
#include <cmath>

namespace fahr::device {

ThermalModel::ThermalModel(const DeviceModel& model)
    : peak_n_(model.peak_force_n),
      continuous_n_(model.continuous_force_n),
      tau_s_(model.thermal_time_constant.count()),
      derate_start_(model.thermal_derate_start),
      renderable_n_(model.peak_force_n) {}

double ThermalModel::renderable_for(double heat) const {
  if (heat <= derate_start_) return peak_n_;
  if (heat >= 1.0) return continuous_n_;
  const double fraction = (heat - derate_start_) / (1.0 - derate_start_);
  return peak_n_ + fraction * (continuous_n_ - peak_n_);
}

void ThermalModel::update(double force_n, std::chrono::duration<double> dt) {
  const double ratio = force_n / continuous_n_;
  const double source = ratio * ratio;
  // Exact solution of tau dh/dt = source - h for a constant source.
  const double decay = std::exp(-dt.count() / tau_s_);
  heat_ = source + (heat_ - source) * decay;
  heat_ = std::max(heat_, 0.0);
  renderable_n_ = renderable_for(heat_);
}

}  // namespace fahr::device
