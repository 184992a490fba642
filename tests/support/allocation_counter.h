// Counts heap allocations made by the current thread, to prove a real-time
// path allocates nothing. Linking fahr::test_allocation_counter replaces the
// global operator new of the test binary, aligned and nothrow forms
// included (one such binary per test group, and never under sanitizers,
// which replace operator new themselves: tests that count are compiled out
// where FAHR_SANITIZE_BUILD is defined).
#pragma once

namespace fahr::test {

// While alive, counts the allocations of the thread that created it.
class AllocationCounter {
 public:
  AllocationCounter();
  ~AllocationCounter();
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;
  // Calls of operator new (any form) on this thread so far.
  long count() const;
  // Allocations reported through count_other_allocation() on this thread so
  // far: allocators that bypass operator new, e.g. SuiteSparse's malloc.
  long other_count() const;
};

// Counts one allocation made outside operator new (a C library's allocation
// hook calls it) for the counter alive on this thread; nothing without one.
void count_other_allocation();

}  // namespace fahr::test
