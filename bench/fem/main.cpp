// fem_bench: tables for the FEM library. Usage:
//   fem_bench [cantilever|leaf|scale|target|compliance|all] [--quick]
//             [--static-max n] [--dynamic-max n]   (cantilever cross-section cells,
//             defaults 16 and 16; --quick: 6 and 4, no 80k mesh) [--markdown [FILE]]
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "bench_util.h"
#include "fahr/bench_support/results_file.h"

namespace fahr::fem::bench {
void run_cantilever(int max_dynamic_n, int max_static_n, int steps);
void run_leaf();
void run_scale(bool quick);
void run_target();
void run_compliance(bool quick);
}  // namespace fahr::fem::bench

int main(int argc, char** argv) {
  using namespace fahr::fem::bench;
  // CHOLMOD 3's supernodal code opens OpenMP regions with a fixed thread
  // count (not OMP_NUM_THREADS), whose spinning workers take the second core
  // of this 2-core machine. libgomp reads OMP_THREAD_LIMIT once at load, so
  // the bench re-executes itself with the limits set: one core, as the
  // targets say. FAHR_BENCH_THREADS=any skips this.
  if (std::getenv("OMP_THREAD_LIMIT") == nullptr && std::getenv("FAHR_BENCH_THREADS") == nullptr) {
    setenv("OMP_THREAD_LIMIT", "1", 1);
    setenv("OMP_WAIT_POLICY", "passive", 1);
    setenv("OPENBLAS_NUM_THREADS", "1", 1);
    execv("/proc/self/exe", argv);
    std::perror("re-exec with OMP_THREAD_LIMIT=1 failed; continuing");
  }
  fahr::bench_support::MarkdownResults results(argc, argv);
  std::string what = "all";
  bool quick = false;
  int static_max = 0;
  int dynamic_max = 0;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) {
      quick = true;
    } else if (std::strcmp(argv[i], "--static-max") == 0 && i + 1 < argc) {
      static_max = std::atoi(argv[++i]);
    } else if (std::strcmp(argv[i], "--dynamic-max") == 0 && i + 1 < argc) {
      dynamic_max = std::atoi(argv[++i]);
    } else {
      what = argv[i];
    }
  }
  if (static_max == 0) static_max = quick ? 6 : 16;
  if (dynamic_max == 0) dynamic_max = quick ? 4 : 16;
  results.begin("fem-" + what + (quick ? "-quick" : ""));
  std::printf("# fem_bench (%s)\n%s\n", what.c_str(), pin_blas_to_one_thread().c_str());
  if (what == "cantilever" || what == "all") run_cantilever(dynamic_max, static_max, 60);
  if (what == "leaf" || what == "all") run_leaf();
  if (what == "scale" || what == "all") run_scale(quick);
  if (what == "compliance" || what == "all") run_compliance(quick);
  if (what == "target" || what == "all") run_target();
  return 0;
}
