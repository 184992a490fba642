// Where a FEM step's thread CPU goes, part by part: the figures that say
// which part to make cheaper when the FEM cannot keep its period. Filled by
// Body::step and ContactStep::step into their StepReport; read by the
// lockstep harness (fahr_stack_sim_run prints them).
#pragma once

#include <cstdint>

namespace fahr::fem {

struct StepParts {
  std::int64_t forces_ns = 0;       // elastic forces (and energy) at x^n
  std::int64_t system_ns = 0;       // installing a finished factor, starting the next, assembly
  std::int64_t solve_ns = 0;        // A v' = M v + h f through the factor
  std::int64_t line_search_ns = 0;  // the energy along the step (Stable Neo-Hookean)
  std::int64_t compliance_ns = 0;   // the W block's new spheres, the free centres
  std::int64_t projection_ns = 0;   // contacts through W, tool and anatomy projection
  std::int64_t supports_ns = 0;     // the anatomy's springs for the next step
  std::int64_t total_ns() const {
    return forces_ns + system_ns + solve_ns + line_search_ns + compliance_ns + projection_ns +
           supports_ns;
  }
};

// CPU time of the calling thread, ns (CLOCK_THREAD_CPUTIME_ID).
std::int64_t thread_cpu_ns() noexcept;

}  // namespace fahr::fem
