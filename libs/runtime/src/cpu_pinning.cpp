// CPU lists and process pinning (see cpu_pinning.h).
#include "fahr/runtime/cpu_pinning.h"

#include <sched.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <stdexcept>
#include <string_view>

namespace fahr::runtime {
namespace {

int parse_cpu(std::string_view text, const std::string& list) {
  int cpu = -1;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), cpu);
  if (text.empty() || error != std::errc() || end != text.data() + text.size() || cpu < 0 ||
      cpu >= CPU_SETSIZE) {
    throw std::invalid_argument("--cpus: '" + list + "': '" + std::string(text) +
                                "' is not a CPU number (a list such as 0, 1,3 or 0-2)");
  }
  return cpu;
}

std::string allowed_cpus(const cpu_set_t& set) {
  std::string out;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &set)) out += (out.empty() ? "" : ",") + std::to_string(cpu);
  }
  return out;
}

}  // namespace

std::vector<int> parse_cpu_list(const std::string& list) {
  std::vector<int> cpus;
  std::string_view rest = list;
  while (true) {
    const std::size_t comma = rest.find(',');
    const std::string_view item = rest.substr(0, comma);
    const std::size_t dash = item.find('-');
    if (dash == std::string_view::npos) {
      cpus.push_back(parse_cpu(item, list));
    } else {
      const int first = parse_cpu(item.substr(0, dash), list);
      const int last = parse_cpu(item.substr(dash + 1), list);
      if (last < first)
        throw std::invalid_argument("--cpus: '" + list + "': range '" + std::string(item) +
                                    "' runs backwards");
      for (int cpu = first; cpu <= last; ++cpu) cpus.push_back(cpu);
    }
    if (comma == std::string_view::npos) break;
    rest = rest.substr(comma + 1);
  }
  std::sort(cpus.begin(), cpus.end());
  if (std::adjacent_find(cpus.begin(), cpus.end()) != cpus.end()) {
    throw std::invalid_argument("--cpus: '" + list + "' names a CPU twice");
  }
  return cpus;
}

void pin_to_cpus(const std::string& list) {
  if (list.empty()) return;
  const std::vector<int> cpus = parse_cpu_list(list);
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof(allowed), &allowed) != 0) {
    throw std::runtime_error(std::string("--cpus: cannot read this process's CPUs: ") +
                             std::strerror(errno));
  }
  cpu_set_t wanted;
  CPU_ZERO(&wanted);
  for (const int cpu : cpus) {
    if (!CPU_ISSET(cpu, &allowed)) {
      throw std::invalid_argument("--cpus: CPU " + std::to_string(cpu) +
                                  " is not one this process may run on (" + allowed_cpus(allowed) +
                                  ")");
    }
    CPU_SET(cpu, &wanted);
  }
  if (sched_setaffinity(0, sizeof(wanted), &wanted) != 0) {
    throw std::runtime_error("--cpus: '" + list + "': " + std::strerror(errno));
  }
}

}  // namespace fahr::runtime
