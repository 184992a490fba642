// Counts heap allocations made by the current thread, to prove a real-time
// path allocates nothing. Linking fahr::test_allocation_counter replaces the
// global operator new of the test binary (one such binary per test group,
// and never under sanitizers, which replace operator new themselves).
#pragma once

namespace fahr::test {

// While alive, counts the allocations of the thread that created it.
class AllocationCounter {
 public:
  AllocationCounter();
  ~AllocationCounter();
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;
  long count() const;
};

}  // namespace fahr::test
