// Refusing a ContactSet allocates nothing (the FEM step allocates nothing
// once its containers are sized; the refusal must not change that).
#include <gtest/gtest.h>

#include "allocation_counter.h"
#include "fahr/fem_service/layout_check.h"

namespace fahr::fem_service {
namespace {

TEST(LayoutRefusal, AcceptAndRefuseAllocateNothing) {
  LayoutCheck check(42);
  long allocations = 0;
  {
    const test::AllocationCounter counter;
    for (std::uint64_t theirs : {42ULL, 7ULL, 7ULL, 42ULL, 8ULL}) check.accept(theirs);
    allocations = counter.count();
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(check.refused(), 3u);
  EXPECT_NE(check.take_error(), "");
}

}  // namespace
}  // namespace fahr::fem_service
