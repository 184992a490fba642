// One thread for the sparse solver's libraries. CHOLMOD 3 opens OpenMP
// regions with a fixed thread count (OMP_NUM_THREADS does not bound it) and
// libopenblas0-pthread starts BLAS threads; their workers spin on the other
// core, which on a 2-core station is the haptic service's. Measured on the
// 8 s intubation (fahr_stack_sim_run): FEM step CPU median 22.4 -> 14.9 ms
// and the run's wall time 38.8 -> 17.5 s with them held to one thread, the
// same output hashes. libgomp reads OMP_THREAD_LIMIT once, when it is
// loaded, so the variables must be in the environment before main(): this
// re-executes the program with them set.
#pragma once

namespace fahr::common {

// If OMP_THREAD_LIMIT is unset and FAHR_SOLVER_THREADS is not "any", sets
// OMP_THREAD_LIMIT=1, OMP_WAIT_POLICY=passive and OPENBLAS_NUM_THREADS=1 (and
// on an x86-64 CPU with AVX2 and FMA, OPENBLAS_CORETYPE=Haswell unless set) and
// re-executes the program (its path from /proc/self/exe) with `argv`; returns only if that is not
// needed or failed (then it prints why and the program runs on as it is). Call first in main(),
// before any thread starts. FAHR_SOLVER_THREADS=any keeps the libraries' own threading (a station
// with cores to spare).
void run_solver_libraries_on_one_thread(char** argv);

}  // namespace fahr::common
