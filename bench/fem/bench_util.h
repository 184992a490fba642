// Timing, table and scene helpers of fem_bench.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "fahr/fem/body.h"
#include "fahr/fem/box_mesh.h"

namespace fahr::fem::bench {

using Clock = std::chrono::steady_clock;

inline double ms_since(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// CPU time of the calling thread, ms: on a shared machine wall time includes
// the time other processes held the core; the tables report both.
double thread_cpu_ms();

// Pins OpenBLAS (CHOLMOD's supernodal BLAS) to one thread if it is the BLAS
// loaded; returns a line saying what happened.
std::string pin_blas_to_one_thread();

struct SolverCase {
  std::string name;
  SolverSettings solver;
};

// The solver configurations every table uses.
SolverCase cholmod_exact();
SolverCase cholmod_lagged(int period);
SolverCase cg_jacobi(double tolerance, int max_iterations);
SolverCase cg_lagged(int period, double tolerance, int max_iterations);

std::vector<std::uint32_t> nodes_where_y_below(const BodyMesh& mesh, double y_m);

struct StepTiming {
  double mean_cpu_ms = 0.0;
  double mean_ms = 0.0;
  double max_ms = 0.0;
  double mean_iterations = 0.0;
  int refactorisations = 0;
};

// Steps `body` `steps` times after `warmup` untimed steps.
StepTiming time_steps(Body& body, int warmup, int steps);

}  // namespace fahr::fem::bench
