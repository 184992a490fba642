// contact_bench [punch|overshoot|smoothness|all]: prints tables anyone can rerun.
#include <cstdio>
#include <cstring>

#include "bench.h"

int main(int argc, char** argv) {
  const char* which = argc > 1 ? argv[1] : "all";
  const bool all = std::strcmp(which, "all") == 0;
  int failures = 0;
  if (all || std::strcmp(which, "punch") == 0) failures += fahr::contact::bench::run_punch();
  if (all || std::strcmp(which, "overshoot") == 0) failures += fahr::contact::bench::run_overshoot();
  if (all || std::strcmp(which, "smoothness") == 0) failures += fahr::contact::bench::run_smoothness();
  std::printf("%s\n", failures == 0 ? "all targets met" : "some targets missed");
  return failures == 0 ? 0 : 1;
}
