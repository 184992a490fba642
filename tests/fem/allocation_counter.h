// Counts heap allocations of this test binary while enabled: global operator
// new (replaced in allocation_counter.cpp) and SuiteSparse's malloc hooks.
#pragma once

#include <cstddef>

namespace fahr::fem::test {

void enable_allocation_counting(bool on);
std::size_t new_count();
std::size_t suitesparse_alloc_count();
void reset_allocation_counts();
// Routes SuiteSparse's malloc/calloc/realloc through the counter.
void hook_suitesparse_allocations();

}  // namespace fahr::fem::test
