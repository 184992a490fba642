// Material defaults and their sources.
#include "fahr/fem/material.h"

#include <cmath>

namespace fahr::fem {

// Stiffness: Cheng, Gandevia, Green, Sinkus and Bilston measured the tongue of
// seven adults in vivo with magnetic resonance elastography and report a
// storage shear modulus of 2.67 +- 0.29 kPa ("Viscoelastic properties of the
// tongue and soft palate using MR elastography", J Biomech 44(3):450-454,
// 2011, https://pubmed.ncbi.nlm.nih.gov/21040923/). With nu = 0.45,
// E = 2 G (1 + nu) = 7.74 kPa. Neonatal values were not found; adult tissue
// stands in until a measurement exists.
// Poisson ratio: muscle is nearly incompressible (nu near 0.5), but linear
// tetrahedra lock volumetrically as nu approaches 0.5; 0.45 is the usual
// compromise in surgical simulation and matches the project's solver notes.
// Density: skeletal muscle is about 1040-1060 kg/m^3; 1040 is used.
// Compression stiffening: Gerard, Ohayon, Luboz, Perrier and Payan indented
// fresh cadaver tongue and fitted a Yeoh solid, W = C10 (I1 - 3) +
// C20 (I1 - 3)^2 ("Non-linear elastic properties of the lingual and facial
// tissues assessed by indentation technique. Application to the
// biomechanics of speech production", Med Eng Phys 27(10):884-892, 2005),
// quoted as C10 = 192 Pa, C20 = 90 Pa. Tongue models built on it keep its
// shape and scale it to living tissue: Buchaillard, Perrier and Payan
// (J Acoust Soc Am 126(4):2033-2051, 2009) use C10 = 1037 Pa, C20 = 486 Pa,
// as does ArtiSynth's tongue (artisynth_models: MooneyRivlinMaterial(1037,
// 0, 0, 486, 0, 10370), "[Buchaillard 2009]"); another ArtiSynth model uses
// 2500 Pa and 1175 Pa after Nazari et al. (Motor Control). C20/C10 is the
// same in all three: 0.469, 0.469, 0.470. Only the ratio is used here, so
// the small-strain modulus stays E: kTongueYeohC20OverC10 = 0.47. The 1037
// / 486 and 2500 / 1175 pairs were read in ArtiSynth's public source; the
// 2005 paper's own table was not at hand (192 / 90 is as quoted).
// Damping: alpha and beta are numerical choices (a lowest tongue mode near
// 5 Hz gets a few percent of critical damping from alpha; beta damps the
// high-frequency element modes), not measurements.
Material neonatal_tongue() {
  Material material;
  material.youngs_modulus_pa = 2.0 * 2670.0 * (1.0 + 0.45);
  material.poisson_ratio = 0.45;
  material.density_kg_per_m3 = 1040.0;
  material.rayleigh_mass_per_s = 1.0;
  material.rayleigh_stiffness_s = 0.01;
  return material;
}

LameParameters lame_parameters(const Material& material) {
  const double e = material.youngs_modulus_pa;
  const double nu = material.poisson_ratio;
  LameParameters lame;
  lame.mu_pa = e / (2.0 * (1.0 + nu));
  lame.lambda_pa = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  return lame;
}

const char* validate(const Material& material) {
  if (!(material.youngs_modulus_pa > 0.0) || !std::isfinite(material.youngs_modulus_pa)) {
    return "material.youngs_modulus_pa must be finite and > 0";
  }
  // nu = 0.5 divides by zero in lambda; negative ratios are legal physics but
  // not tissue, and below -1 the material is unstable.
  if (!(material.poisson_ratio > -1.0 && material.poisson_ratio < 0.5)) {
    return "material.poisson_ratio must be in (-1, 0.5)";
  }
  if (!(material.density_kg_per_m3 > 0.0) || !std::isfinite(material.density_kg_per_m3)) {
    return "material.density_kg_per_m3 must be finite and > 0";
  }
  if (!(material.rayleigh_mass_per_s >= 0.0) || !(material.rayleigh_stiffness_s >= 0.0)) {
    return "material Rayleigh coefficients must be >= 0";
  }
  if (!(material.yeoh_c20_over_c10 >= 0.0 && material.yeoh_c20_over_c10 <= kMaxYeohC20OverC10)) {
    return "material.yeoh_c20_over_c10 must be in [0, 100]";
  }
  if (material.model != MaterialModel::kCorotational &&
      material.model != MaterialModel::kStableNeoHookean) {
    return "material.model must be corotational or stable_neo_hookean";
  }
  return "";
}

}  // namespace fahr::fem
