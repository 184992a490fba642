// SuiteSparse's allocation hooks, counted (see suitesparse_allocations.h).
#include "suitesparse_allocations.h"

#include <SuiteSparse_config.h>

#include <cstdlib>

#include "allocation_counter.h"

namespace fahr::fem::test {
namespace {

void* count_malloc(std::size_t size) {
  fahr::test::count_other_allocation();
  return std::malloc(size);
}
void* count_calloc(std::size_t n, std::size_t size) {
  fahr::test::count_other_allocation();
  return std::calloc(n, size);
}
void* count_realloc(void* p, std::size_t size) {
  fahr::test::count_other_allocation();
  return std::realloc(p, size);
}

}  // namespace

void hook_suitesparse_allocations() {
  SuiteSparse_config.malloc_func = count_malloc;
  SuiteSparse_config.calloc_func = count_calloc;
  SuiteSparse_config.realloc_func = count_realloc;
}

}  // namespace fahr::fem::test
