// Counts global operator new calls of this test binary while enabled.
#pragma once

#include <cstddef>

namespace fahr::contact::test {

void count_allocations(bool on);
std::size_t allocations();

}  // namespace fahr::contact::test
