// Gradient and surface projection shared by every implicit solid.
#include "fahr/scenegen/implicit_solid.h"

namespace fahr::scenegen {
namespace {

constexpr double kGradientStepMm = 1e-4;
constexpr int kNewtonSteps = 6;

}  // namespace

Vec3 ImplicitSolid::gradient(const Vec3& p) const {
  Vec3 g;
  for (int i = 0; i < 3; ++i) {
    Vec3 dp = Vec3::Zero();
    dp[i] = kGradientStepMm;
    g[i] = (value(p + dp) - value(p - dp)) / (2.0 * kGradientStepMm);
  }
  return g;
}

Vec3 ImplicitSolid::project_to_surface(const Vec3& p) const {
  Vec3 x = p;
  for (int i = 0; i < kNewtonSteps; ++i) {
    const double f = value(x);
    const Vec3 g = gradient(x);
    const double g2 = g.squaredNorm();
    if (g2 < 1e-12) break;  // flat spot (crease of a max or min): stop where we are
    x -= (f / g2) * g;
  }
  return x;
}

}  // namespace fahr::scenegen
