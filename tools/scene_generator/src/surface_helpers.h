// Helpers shared by the surface builders of this library (not installed).
#pragma once

#include <algorithm>
#include <cmath>
#include <utility>

namespace fahr::scenegen {

inline constexpr double kPi = 3.14159265358979323846;

inline int cells_for(double length_mm, double resolution_mm, int minimum = 2) {
  return std::max(minimum, static_cast<int>(std::ceil(length_mm / resolution_mm)));
}

// Closed rectangle loop in (radial, axial) with sharp corners, parametrised
// by an index so that each side gets its own number of points.
struct RectangleLoop {
  int n_long;   // points along each long side
  int n_short;  // points along each short side
  int size() const { return 2 * (n_long + n_short); }
  // Returns (radial fraction, axial fraction) for loop index j.
  std::pair<double, double> at(int j) const {
    j %= size();
    const auto f = [](int k, int n) { return static_cast<double>(k) / static_cast<double>(n); };
    if (j < n_long) return {0.0, f(j, n_long)};  // inner side, top to bottom
    j -= n_long;
    if (j < n_short) return {f(j, n_short), 1.0};  // bottom end, inner to outer
    j -= n_short;
    if (j < n_long) return {1.0, 1.0 - f(j, n_long)};  // outer side, bottom to top
    j -= n_long;
    return {1.0 - f(j, n_short), 0.0};  // top end, outer to inner
  }
};

inline int loop_index(double fraction, int size) {
  return static_cast<int>(std::lround(fraction * static_cast<double>(size))) % size;
}

}  // namespace fahr::scenegen
