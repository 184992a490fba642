// contact_bench [punch|overshoot|smoothness|all] | property [--runs N] [--seconds S]
//   [--threads T] [--first R], each with [--markdown [FILE]]: prints tables anyone can rerun.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "bench.h"
#include "fahr/bench_support/results_file.h"

int main(int argc, char** argv) {
  // The re-execution below passes --markdown on; the bench's own arguments lack it.
  std::vector<char*> original(argv, argv + argc + 1);
  fahr::bench_support::MarkdownResults results(argc, argv);
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
      execv("/proc/self/exe", original.data());
      std::perror("re-exec with OMP_THREAD_LIMIT=1 failed; continuing");
    }
    results.begin("contact-property", fahr::bench_support::MarkdownResults::Output::kText);
    return fahr::contact::bench::run_property(argc - 2, argv + 2);
  }
  const bool all = std::strcmp(which, "all") == 0;
  results.begin(std::string("contact-") + which,
                fahr::bench_support::MarkdownResults::Output::kText);
  int failures = 0;
  if (all || std::strcmp(which, "punch") == 0) failures += fahr::contact::bench::run_punch();
  if (all || std::strcmp(which, "overshoot") == 0)
    failures += fahr::contact::bench::run_overshoot();
  if (all || std::strcmp(which, "smoothness") == 0)
    failures += fahr::contact::bench::run_smoothness();
  std::printf("%s\n", failures == 0 ? "all targets met" : "some targets missed");
  return failures == 0 ? 0 : 1;
}
