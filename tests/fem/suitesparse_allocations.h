// SuiteSparse allocates with malloc, not operator new: routes its
// malloc/calloc/realloc through fahr::test::count_other_allocation(), so an
// AllocationCounter's other_count() sees CHOLMOD's allocations.
#pragma once

namespace fahr::fem::test {

void hook_suitesparse_allocations();

}  // namespace fahr::fem::test
