// Pinning a service to some of the machine's CPUs (--cpus): on a small lab
// PC the haptic tick shares two cores with the FEM, whose step every 5 ms
// evicts the caches the tick reads next; giving each its own core keeps
// the tick's tree and grid warm. Opt-in: by default the kernel places the
// threads.
#pragma once

#include <string>
#include <vector>

namespace fahr::runtime {

// "0", "1,3", "0-2,5": the CPU numbers listed, ascending, no repeats.
// Throws std::invalid_argument naming --cpus and what is wrong.
std::vector<int> parse_cpu_list(const std::string& list);

// Pins the calling thread, and so every thread it starts afterwards (DDS,
// the haptic digest), to the CPUs listed; empty: nothing changes. Call it
// before the participant starts its threads. Throws std::invalid_argument
// naming --cpus when a CPU is not one this process may run on.
void pin_to_cpus(const std::string& list);

}  // namespace fahr::runtime
