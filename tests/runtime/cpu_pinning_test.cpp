// --cpus: the list's grammar, its errors, and pinning to a CPU this process
// may run on (restored afterwards, so the other tests run as before).
#include "fahr/runtime/cpu_pinning.h"

#include <gtest/gtest.h>
#include <sched.h>

#include <stdexcept>
#include <string>

namespace fahr::runtime {
namespace {

std::string error_of(const std::string& list) {
  try {
    parse_cpu_list(list);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(CpuList, ReadsSinglesListsAndRanges) {
  EXPECT_EQ(parse_cpu_list("0"), std::vector<int>{0});
  EXPECT_EQ(parse_cpu_list("3,1"), (std::vector<int>{1, 3}));
  EXPECT_EQ(parse_cpu_list("0-2,5"), (std::vector<int>{0, 1, 2, 5}));
}

TEST(CpuList, NamesTheFlagAndWhatIsWrong) {
  EXPECT_NE(error_of("").find("--cpus: ''"), std::string::npos);
  EXPECT_NE(error_of("a").find("'a' is not a CPU number"), std::string::npos);
  EXPECT_NE(error_of("1,").find("'' is not a CPU number"), std::string::npos);
  EXPECT_NE(error_of("-1").find("is not a CPU number"), std::string::npos);
  EXPECT_NE(error_of("3-1").find("range '3-1' runs backwards"), std::string::npos);
  EXPECT_NE(error_of("0,0-1").find("names a CPU twice"), std::string::npos);
  EXPECT_NE(error_of("99999").find("is not a CPU number"), std::string::npos);
}

TEST(CpuPinning, PinsToAnAllowedCpuAndRefusesOthers) {
  cpu_set_t before;
  CPU_ZERO(&before);
  ASSERT_EQ(sched_getaffinity(0, sizeof(before), &before), 0);
  int first = -1, outside = -1;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &before) && first < 0) first = cpu;
    if (!CPU_ISSET(cpu, &before) && outside < 0) outside = cpu;
  }
  ASSERT_GE(first, 0);
  ASSERT_GE(outside, 0);
  pin_to_cpus(std::to_string(first));
  cpu_set_t now;
  CPU_ZERO(&now);
  ASSERT_EQ(sched_getaffinity(0, sizeof(now), &now), 0);
  EXPECT_EQ(CPU_COUNT(&now), 1);
  EXPECT_TRUE(CPU_ISSET(first, &now));
  try {
    pin_to_cpus(std::to_string(outside));
    ADD_FAILURE() << "CPU " << outside << " was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("is not one this process may run on"), std::string::npos)
        << e.what();
  }
  pin_to_cpus("");  // no change
  ASSERT_EQ(sched_getaffinity(0, sizeof(now), &now), 0);
  EXPECT_EQ(CPU_COUNT(&now), 1);
  ASSERT_EQ(sched_setaffinity(0, sizeof(before), &before), 0);
}

}  // namespace
}  // namespace fahr::runtime
