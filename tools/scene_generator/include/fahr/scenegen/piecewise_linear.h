// Piecewise-linear profile over [0, 1]: anatomical shapes are written as a few
// (fraction, value) knots rather than as formulas with unexplained constants.
#pragma once

#include <initializer_list>
#include <utility>
#include <vector>

namespace fahr::scenegen {

class PiecewiseLinear {
 public:
  PiecewiseLinear(std::initializer_list<std::pair<double, double>> knots) : knots_(knots) {}

  double operator()(double t) const {
    if (t <= knots_.front().first) return knots_.front().second;
    for (size_t i = 1; i < knots_.size(); ++i) {
      if (t <= knots_[i].first) {
        const auto& [t0, v0] = knots_[i - 1];
        const auto& [t1, v1] = knots_[i];
        return v0 + (v1 - v0) * (t - t0) / (t1 - t0);
      }
    }
    return knots_.back().second;
  }

 private:
  std::vector<std::pair<double, double>> knots_;
};

// 0 below edge0, 1 above edge1, C1-smooth in between.
inline double smoothstep(double edge0, double edge1, double x) {
  double t = (x - edge0) / (edge1 - edge0);
  t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
  return t * t * (3.0 - 2.0 * t);
}

}  // namespace fahr::scenegen
