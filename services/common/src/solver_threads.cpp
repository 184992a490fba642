// Re-execution with the solver libraries held to one thread (see solver_threads.h).
#include "fahr/common/solver_threads.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace fahr::common {

void run_solver_libraries_on_one_thread(char** argv) {
  const char* choice = std::getenv("FAHR_SOLVER_THREADS");
  if (std::getenv("OMP_THREAD_LIMIT") != nullptr || (choice != nullptr && std::strcmp(choice, "any") == 0)) return;
  setenv("OMP_THREAD_LIMIT", "1", 1);
  setenv("OMP_WAIT_POLICY", "passive", 1);
  setenv("OPENBLAS_NUM_THREADS", "1", 1);
  execv("/proc/self/exe", argv);
  std::perror("fahr: re-executing with the solver libraries on one thread failed; running as is");
}

}  // namespace fahr::common
