// Projected Gauss-Seidel for the linear complementarity problem
//   S lambda - b >= 0,  lambda >= 0,  lambda . (S lambda - b) = 0
// with S symmetric positive semi-definite, dense, row-major (Cottle, Pang and
// Stone, The Linear Complementarity Problem, 1992, section 5.2; the form
// SOFA's LCPForceFeedback uses). Fixed row order, so results are
// deterministic; rows with S_ii <= 0 cannot push and keep lambda = 0.
#pragma once

#include <cstddef>
#include <cstdint>

namespace fahr::contact {

struct PgsSettings {
  // Sweeps at most per solve. Warm-started from the previous tick, a steady
  // contact needs a few; 200 bounds a 64-row tick to ~1e6 flops (< 0.5 ms).
  int max_sweeps = 200;
  // A sweep whose largest change S_ii |d lambda_i| (a change of gap, m) is
  // below this ends the solve: 1e-8 m is 0.01 um, a thousand times below what
  // a hand feels and a hundredth of the FEM projection tolerance (1 um).
  double tolerance_m = 1e-8;
};

struct PgsReport {
  int sweeps = 0;
  bool converged = true;
  double last_change_m = 0.0;  // largest S_ii |d lambda_i| of the last sweep, m
};

// PGS work over several solves (a tick runs one to a dozen): a row visit
// costs at most one k-long column update (none when its lambda stays), so
// row visits x k bounds the tick's PGS cost.
struct PgsWork {
  std::uint32_t solves = 0;
  std::uint32_t sweeps = 0;
  std::uint32_t unconverged = 0;  // solves that hit max_sweeps
  std::uint64_t row_visits = 0;
  void add(const PgsReport& report, std::size_t k) {
    ++solves;
    sweeps += static_cast<std::uint32_t>(report.sweeps);
    unconverged += report.converged ? 0u : 1u;
    row_visits += static_cast<std::uint64_t>(report.sweeps) * k;
  }
};

// s: k x k, symmetric, row stride `stride` (>= k), m/N. b: k, m. lambda: k,
// N, holds the warm start on entry and the solution on exit. residual: k
// doubles of workspace (b - S lambda on exit).
PgsReport solve_pgs(const double* s, std::size_t stride, std::size_t k, const double* b,
                    double* lambda, double* residual, const PgsSettings& settings);

}  // namespace fahr::contact
