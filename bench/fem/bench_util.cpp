// Helpers shared by the fem_bench tables.
#include "bench_util.h"

#include <dlfcn.h>
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace fahr::fem::bench {

namespace {

// Calls `void name(int)` if the process has it; dlsym hands back void*,
// copied into a function pointer as POSIX allows.
bool call_if_present(const char* name, int value) {
  void* symbol = dlsym(RTLD_DEFAULT, name);
  if (symbol == nullptr) return false;
  using SetThreads = void (*)(int);
  SetThreads set_threads = nullptr;
  static_assert(sizeof(set_threads) == sizeof(symbol));
  std::memcpy(&set_threads, &symbol, sizeof(symbol));
  set_threads(value);
  return true;
}

}  // namespace

double thread_cpu_ms() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return 1e3 * static_cast<double>(now.tv_sec) + 1e-6 * static_cast<double>(now.tv_nsec);
}

std::string pin_blas_to_one_thread() {
  // CHOLMOD's supernodal factorisation calls the BLAS, which with
  // libopenblas0-pthread starts threads, and CHOLMOD itself has OpenMP loops;
  // both wake threads per call, which costs more than it gains on a shared
  // 2-core machine and breaks the "one core" of the targets.
  const bool blas = call_if_present("openblas_set_num_threads", 1);
  const bool omp = call_if_present("omp_set_num_threads", 1);
  return std::string("threads: OpenBLAS ") + (blas ? "pinned to 1" : "absent") + ", OpenMP " +
         (omp ? "pinned to 1" : "absent");
}

SolverCase cholmod_exact() {
  SolverCase c{"cholmod refactor every step", {}};
  c.solver.kind = LinearSolver::kCholmod;
  c.solver.refactor_period = 1;
  return c;
}

// Lagged cases refactorise every `period` steps (0: never by age) and, by
// default, when an element has turned by 0.1 rad since the factorisation.
std::string lag_label(int period) {
  // snprintf rather than string concatenation: GCC 12 raises a false
  // -Wrestrict on operator+ of short strings at -O3.
  char label[48];
  if (period == 0) {
    std::snprintf(label, sizeof(label), "on 0.1 rad");
  } else {
    std::snprintf(label, sizeof(label), "/%d or 0.1 rad", period);
  }
  return label;
}

SolverCase cholmod_lagged(int period) {
  char name[96];
  std::snprintf(name, sizeof(name), "cholmod lagged, refactor %s", lag_label(period).c_str());
  SolverCase c{name, {}};
  c.solver.kind = LinearSolver::kCholmod;
  c.solver.refactor_period = period;
  return c;
}

SolverCase cg_jacobi(double tolerance, int max_iterations) {
  char name[96];
  std::snprintf(name, sizeof(name), "cg jacobi tol %.0e max %d", tolerance, max_iterations);
  SolverCase c{name, {}};
  c.solver.kind = LinearSolver::kConjugateGradient;
  c.solver.preconditioner = CgPreconditioner::kJacobi;
  c.solver.refactor_period = 0;
  c.solver.cg_relative_tolerance = tolerance;
  c.solver.cg_max_iterations = max_iterations;
  return c;
}

SolverCase cg_lagged(int period, double tolerance, int max_iterations) {
  char name[96];
  std::snprintf(name, sizeof(name), "cg lagged-chol %s, tol %.0e max %d", lag_label(period).c_str(),
                tolerance, max_iterations);
  SolverCase c{name, {}};
  c.solver.kind = LinearSolver::kConjugateGradient;
  c.solver.preconditioner = CgPreconditioner::kLaggedCholesky;
  c.solver.refactor_period = period;
  c.solver.cg_relative_tolerance = tolerance;
  c.solver.cg_max_iterations = max_iterations;
  return c;
}

std::vector<std::uint32_t> nodes_where_y_below(const BodyMesh& mesh, double y_m) {
  std::vector<std::uint32_t> nodes;
  for (std::size_t i = 0; i < mesh.nodes_m.size(); ++i) {
    if (mesh.nodes_m[i].y() < y_m) nodes.push_back(static_cast<std::uint32_t>(i));
  }
  return nodes;
}

StepTiming time_steps(Body& body, int warmup, int steps) {
  for (int k = 0; k < warmup; ++k) body.step();
  StepTiming timing;
  double total = 0.0;
  double iterations = 0.0;
  const double cpu_start = thread_cpu_ms();
  for (int k = 0; k < steps; ++k) {
    const auto start = Clock::now();
    const StepReport report = body.step();
    const double ms = ms_since(start);
    total += ms;
    timing.max_ms = std::max(timing.max_ms, ms);
    iterations += report.solver_iterations;
    timing.refactorisations += report.refactorised ? 1 : 0;
  }
  timing.mean_cpu_ms = (thread_cpu_ms() - cpu_start) / steps;
  timing.mean_ms = total / steps;
  timing.mean_iterations = iterations / steps;
  return timing;
}

}  // namespace fahr::fem::bench
