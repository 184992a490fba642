// Compression stiffening: a per-element scale of the corotational linear
// material that gives it the large-strain stiffening of a Yeoh solid, so an
// element that is flattened or crushed pushes back ever harder instead of
// going through itself (material.h has the tissue's figures and sources).
//
// A Yeoh solid, W = C10 (I1bar - 3) + C20 (I1bar - 3)^2 with the isochoric
// invariant I1bar = J^(-2/3) tr(F^T F), has the deviatoric stress of a
// neo-Hookean solid of shear modulus 2 dW/dI1bar, i.e. that stress times
//   s = (dW/dI1bar) / C10 = 1 + 2 (C20 / C10) (I1bar - 3),
// its stiffening relative to small strain. The body multiplies each
// element's corotated force and its block of A by s (a secant scale, taken
// at the start of the step like the rotation): s = 1 at rest and in any
// rotation or uniform volume change (I1bar = 3 there), so the small-strain
// modulus is unchanged, and s grows without bound as J -> 0 at finite
// tr(F^T F), i.e. as the element flattens: a barrier against inversion.
//
// What this is not: a hyperelastic material with its exact tangent. The
// scaled force is not the gradient of an energy (s depends on x), A leaves
// out the force's change through s (ds/dx), and s is frozen over a step, so
// an element driven from rest to inside out within one step meets no
// barrier in that step. The force at the start of each step is exact for
// the scaled material, so the equilibrium does not depend on A (body.h).
// Uniform compression (F = a I) is not stiffened: I1bar is isochoric.
#pragma once

#include <Eigen/Core>

namespace fahr::fem {

// Upper bound of s. It bounds how much stiffer than its neighbours one
// element's block of A can get (the condition number of A grows with it)
// and how far a linearised step can overshoot when s changes within a step.
// On the Yeoh curve with the tongue's C20/C10 = 0.47, s = 100 is an element
// flattened to a quarter of a percent of its thickness (F = diag(1, 1, J),
// J = 0.0025); an inverted element (J <= 0) gets this scale.
inline constexpr double kMaxStiffeningScale = 100.0;

// s for a deformation gradient F (rest to current, dimensionless) and the
// Yeoh ratio C20/C10 (>= 0; 0 returns exactly 1). J <= 0 (flat or inverted)
// or a non-finite F returns kMaxStiffeningScale. In [1, kMaxStiffeningScale].
double stiffening_scale(const Eigen::Matrix3d& deformation_gradient, double c20_over_c10);

}  // namespace fahr::fem
