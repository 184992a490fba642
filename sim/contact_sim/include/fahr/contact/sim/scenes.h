// Scenes shared by tests/contact and bench/contact.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fahr/contact/sim/fem_driver.h"
#include "fahr/contact/sim/graded_block.h"
#include "fahr/fem/material.h"

namespace fahr::contact::sim {

// Neonatal tongue material without gravity: Boussinesq and the overshoot
// checks measure from an unloaded rest state.
fem::BodySettings block_body_settings(double fem_period_s);

struct PunchScene {
  BlockScene block;
  std::vector<std::uint32_t> sphere_nodes;  // top nodes under the punch, one sphere each
  double punch_radius_m = 0.0;              // a as asked, m
  // Area-equivalent radius of the nodes under the punch, m: each fine top
  // node carries s^2 of surface, so a_eff = s sqrt(N / pi). The FEM's punch.
  double effective_radius_m = 0.0;
  double sphere_radius_m = 0.0002;  // node spheres, m
  std::unique_ptr<FemDriver> fem;
};

// The punch block's mesh in units of the punch radius a.
struct PunchMesh {
  double cells_per_radius = 3.125;  // fine cells per a under the punch (29 spheres)
  double block_radii = 40.0;        // block half-width and depth, in a
  double growth = 1.5;              // cell growth ratio away from the punch
};
// Accurate (the FEM alone within ~7 % of Boussinesq; 61k tets, ~20 s per run).
inline constexpr PunchMesh kAccuratePunchMesh{};
// Small and fast, for behaviour rather than accuracy (overshoot, smoothness).
inline constexpr PunchMesh kSmallPunchMesh{2.5, 4.0, 1.5};

// A flat punch of radius `punch_radius_m` on a graded neonatal-tissue block.
// recompute_compliance: refactorise every step, so W (which follows the
// factorisation) is exact every step instead of the rest W.
PunchScene make_punch_scene(double punch_radius_m, double fem_period_s, std::string& error,
                            const PunchMesh& mesh = kAccuratePunchMesh,
                            bool recompute_compliance = false);

// The ~500-tet scene of the property tests: a 20 x 8 x 20 mm block of
// 6 x 2 x 6 cells (432 tets), 1 mm node spheres on its 49 top nodes, all
// with W.
struct SmallScene {
  BlockScene block;
  std::unique_ptr<FemDriver> fem;
};
SmallScene make_small_scene(double fem_period_s, std::string& error);

}  // namespace fahr::contact::sim
