// FEM solver choices: linear solver, Algorithm 1 projection, and
// the contact compliance the haptic loop solves on.
#pragma once

#include <chrono>
#include <string_view>

#include "fahr/scene/defaults.h"

namespace fahr::scene {

enum class LinearSolver {
  kCholmod,  // sparse direct (SuiteSparse), factorised when the matrix changes
  kPcg,      // preconditioned conjugate gradient, warm-started, budgeted
};

enum class ComplianceMode {
  kExact,   // W = J A^-1 J^T from the current factorisation
  kLagged,  // W of the previous factorisation (cheaper, one step old)
  kNone,    // no compliance: the haptic loop sees only positions
};

// How W is laid out: 3x3 blocks a sphere pair (the haptic loop projects
// them on its own normals), or one column a sphere along the normal of its
// ContactSet entry (three times the spheres for the same solves).
enum class ComplianceColumns {
  kBlocks,
  kNormals,
};

std::string_view to_string(LinearSolver solver);
std::string_view to_string(ComplianceMode mode);
std::string_view to_string(ComplianceColumns columns);

struct FemSolverSettings {
  LinearSolver linear_solver = LinearSolver::kCholmod;
  double cg_tolerance = kDefaultCgTolerance;                        // relative residual, (0, 1)
  int cg_max_iterations = kDefaultCgMaxIterations;                  // [1, 100000]
  int projection_max_iterations = kDefaultProjectionMaxIterations;  // [1, 10000]
  double projection_tolerance_m = kDefaultProjectionToleranceM;     // m, (0, 1e-2]
  ComplianceMode compliance = ComplianceMode::kExact;
  ComplianceColumns compliance_columns = ComplianceColumns::kBlocks;
  int max_candidate_contacts = kDefaultMaxCandidateContacts;  // [0, 1024]
  // ContactSets older than this are ignored and counted, (0, 10 s].
  std::chrono::nanoseconds max_contact_age = kDefaultMaxContactAge;
  double sleep_speed_mps = kDefaultSleepSpeedMps;  // m/s, [0, 1]
  // No tet ends a FEM step below this share of its rest volume
  // (libs/fem volume_floor.h), [0, 0.9]; 0: no floor.
  double volume_floor_ratio = 0.0;
  // A refactorisation runs beside the step and is used this long after it
  // began (libs/fem SolverSettings::background_factor_latency_s), [0, 1 s];
  // 0: inside the step.
  std::chrono::nanoseconds factor_latency{0};
};

}  // namespace fahr::scene
