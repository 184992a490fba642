// fahr_bench_results NAME [--markdown [FILE]] [--started S LOAD] [-- COMMAND...]:
// copies its standard input to its standard output and, with --markdown,
// into the results file of NAME (bench/results/<machine>/NAME.md by
// default) under the header every bench writes, naming COMMAND as the
// command. For scripts whose tables come from several programs
// (bench/intubation.sh). --started: the script ran S seconds before it
// piped its tables here (bash's $SECONDS), and LOAD is the load average it
// began at (the first three fields of /proc/loadavg); the file's wall time
// and load at start are then the script's.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "fahr/bench_support/results_file.h"

int main(int argc, char** argv) {
  using fahr::bench_support::MarkdownResults;
  try {
    MarkdownResults results(argc, argv);
    std::string name;
    std::string command;
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      if (arg == "--") {
        command = fahr::bench_support::command_line(argc - i - 1, argv + i + 1);
        break;
      }
      if (arg == "--started") {
        char* end = nullptr;
        const double elapsed = i + 2 < argc ? std::strtod(argv[i + 1], &end) : -1.0;
        if (end == nullptr || *end != '\0' || !(elapsed >= 0.0)) {
          std::fprintf(stderr, "fahr_bench_results: --started needs SECONDS (>= 0) and LOAD\n");
          return 2;
        }
        results.record_script_start(elapsed, argv[i + 2]);
        i += 2;
        continue;
      }
      if (!name.empty() || arg.rfind("-", 0) == 0) {
        std::fprintf(stderr,
                     "usage: %s NAME [--markdown [FILE]] [--started S LOAD] [-- COMMAND...]\n",
                     argv[0]);
        return 2;
      }
      name = arg;
    }
    if (name.empty()) {
      std::fprintf(stderr,
                   "usage: %s NAME [--markdown [FILE]] [--started S LOAD] [-- COMMAND...]\n",
                   argv[0]);
      return 2;
    }
    if (!command.empty()) results.record_script(command);
    results.begin(name);
    char buffer[4096];
    for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, stdin)) > 0;) {
      std::fwrite(buffer, 1, n, stdout);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fahr_bench_results: %s\n", e.what());
    return 1;
  }
}
