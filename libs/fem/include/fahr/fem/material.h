// Elastic material in SI units, its model, and Rayleigh damping coefficients.
#pragma once

namespace fahr::fem {

// How a body's elements turn deformation into force (docs/design/fem-step-and-solvers.md).
enum class MaterialModel {
  // Isotropic linear elasticity in each element's rotated frame
  // (corotation.h); with yeoh_c20_over_c10 > 0 scaled per element by the
  // compression-stiffening secant (compression_stiffening.h).
  kCorotational,
  // Stable Neo-Hookean (Smith, de Goes and Kim 2018) with the tongue's Yeoh
  // term (stable_neo_hookean.h): an energy defined through inversion, its
  // exact force every step and its projected tangent in A.
  kStableNeoHookean,
};

// Isotropic elasticity (E and nu set the small-strain moduli of either
// model) and Rayleigh damping D = alpha M + beta K.
struct Material {
  double youngs_modulus_pa = 7740.0;   // E, Pa, > 0
  double poisson_ratio = 0.45;         // nu, dimensionless, in [0, 0.5)
  double density_kg_per_m3 = 1040.0;   // rho, kg/m^3, > 0
  double rayleigh_mass_per_s = 1.0;    // alpha, 1/s, >= 0
  double rayleigh_stiffness_s = 0.01;  // beta, s, >= 0
  // Compression stiffening, the Yeoh ratio C20/C10, dimensionless,
  // [0, kMaxYeohC20OverC10]; the tongue's is kTongueYeohC20OverC10.
  // Corotational: the per-element secant scale (compression_stiffening.h),
  // 0 the linear material exactly as without it. Stable Neo-Hookean: the
  // Yeoh term of the energy (stable_neo_hookean.h), 0 none.
  double yeoh_c20_over_c10 = 0.0;
  MaterialModel model = MaterialModel::kCorotational;
};

// Gerard et al.'s Yeoh fit of human tongue tissue, C20/C10 = 0.47 (see
// material.cpp for the source and the figures).
inline constexpr double kTongueYeohC20OverC10 = 0.47;
// Beyond this the stiffening is no longer a tissue's: at C20/C10 = 100 an
// incompressible 10 % shortening (I1bar - 3 = 0.032) already multiplies the
// stress by 7.4.
inline constexpr double kMaxYeohC20OverC10 = 100.0;

// Defaults for neonatal tongue tissue. No neonatal measurement is known to
// us; the stiffness is the adult in-vivo value, see material.cpp for sources.
// Compression stiffening stays off here (the scene file turns it on).
Material neonatal_tongue();

struct LameParameters {
  double lambda_pa = 0.0;  // first Lame parameter, Pa
  double mu_pa = 0.0;      // shear modulus, Pa
};

LameParameters lame_parameters(const Material& material);

// Empty when valid, otherwise a sentence naming the offending field.
const char* validate(const Material& material);

}  // namespace fahr::fem
