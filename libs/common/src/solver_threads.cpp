// Re-execution with the solver libraries held to one thread (see solver_threads.h).
#include "fahr/common/solver_threads.h"

#include <limits.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace fahr::common {

void run_solver_libraries_on_one_thread(char** argv) {
  const char* choice = std::getenv("FAHR_SOLVER_THREADS");
  if (std::getenv("OMP_THREAD_LIMIT") != nullptr ||
      (choice != nullptr && std::strcmp(choice, "any") == 0))
    return;
  // The program's own path, not /proc/self/exe: exec'ing that link would
  // rename the process "exe" for ps, pgrep and killall.
  char path[PATH_MAX];
  const ssize_t length = readlink("/proc/self/exe", path, sizeof(path) - 1);
  // FAHR_SOLVER_THREADS=any in the child as well: should the environment
  // not take the limits, the child runs as is instead of re-executing again.
#if defined(__x86_64__)
  // OpenBLAS picks its kernels by the CPU's model. A virtual CPU it does not
  // know (a cloud "Intel Xeon Processor" with AVX-512) gets its generic
  // Prescott kernels, several times slower in CHOLMOD's factorisation, and
  // an AVX-512 one it knows gets kernels that round differently from the
  // recorded hashes' (lockstep.md). Haswell's where AVX2 and FMA are there;
  // a value the user set is kept.
  if (std::getenv("OPENBLAS_CORETYPE") == nullptr && __builtin_cpu_supports("avx2") &&
      __builtin_cpu_supports("fma") && setenv("OPENBLAS_CORETYPE", "Haswell", 1) != 0) {
    std::fprintf(stderr, "fahr: cannot set OPENBLAS_CORETYPE; OpenBLAS chooses its kernels\n");
  }
#endif
  if (length <= 0 || setenv("OMP_THREAD_LIMIT", "1", 1) != 0 ||
      setenv("OMP_WAIT_POLICY", "passive", 1) != 0 || setenv("OPENBLAS_NUM_THREADS", "1", 1) != 0 ||
      setenv("FAHR_SOLVER_THREADS", "any", 1) != 0) {
    std::fprintf(stderr, "fahr: cannot hold the solver libraries to one thread; running as is\n");
    return;
  }
  path[length] = '\0';
  execv(path, argv);
  std::perror("fahr: re-executing with the solver libraries on one thread failed; running as is");
}

}  // namespace fahr::common
