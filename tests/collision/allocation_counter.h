// Counts global operator new calls while armed, so a test can prove that a
// path allocates nothing (in the spirit of Eigen's nomalloc test).
#pragma once

#include <cstddef>

namespace fahr::collision::test {

void arm_allocation_counter();
// Disarms and returns the allocations seen since arm_allocation_counter().
std::size_t disarm_allocation_counter();

}  // namespace fahr::collision::test
