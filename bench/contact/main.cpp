// contact_bench [punch|overshoot|smoothness|all] | property [--runs N] [--seconds S]
//   [--threads T] [--first R]: prints tables anyone can rerun.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "bench.h"

int main(int argc, char** argv) {
  const char* which = argc > 1 ? argv[1] : "all";
  // Not part of "all": 10,000 runs take minutes.
  if (std::strcmp(which, "property") == 0) {
    // One thread per run: CHOLMOD's OpenMP workers and OpenBLAS threads
    // would only spin against the runs' own threads. libgomp reads the limit
    // at load, hence the re-execution (as fem_bench does).
    if (std::getenv("OMP_THREAD_LIMIT") == nullptr) {
      setenv("OMP_THREAD_LIMIT", "1", 1);
      setenv("OMP_WAIT_POLICY", "passive", 1);
      setenv("OPENBLAS_NUM_THREADS", "1", 1);
      execv("/proc/self/exe", argv);
      std::perror("re-exec with OMP_THREAD_LIMIT=1 failed; continuing");
    }
    return fahr::contact::bench::run_property(argc - 2, argv + 2);
  }
  const bool all = std::strcmp(which, "all") == 0;
  int failures = 0;
  if (all || std::strcmp(which, "punch") == 0) failures += fahr::contact::bench::run_punch();
  if (all || std::strcmp(which, "overshoot") == 0)
    failures += fahr::contact::bench::run_overshoot();
  if (all || std::strcmp(which, "smoothness") == 0)
    failures += fahr::contact::bench::run_smoothness();
  std::printf("%s\n", failures == 0 ? "all targets met" : "some targets missed");
  return failures == 0 ? 0 : 1;
}
