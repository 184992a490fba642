// Results files of the benches: bench/results/<machine>/<name>.md, written
// by the bench itself under a header that says where and how the figures
// were taken (command, commit, machine, BLAS, date, load).
//
// A bench keeps printing its tables with printf; MarkdownResults copies
// everything it prints on stdout from begin() on into the file, so the
// tables are formatted once and the file holds exactly what the console
// showed.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>
#include <utility>

namespace fahr::bench_support {

// One line for a bench's --help.
inline constexpr const char* kMarkdownHelp =
    "--markdown [FILE]: also write the output to FILE (a name ending in .md; or "
    "--markdown=FILE), by default bench/results/<machine>/<name>.md in the source tree, "
    "under a header naming the command, commit, machine and date";

struct Machine {
  std::string cpu_model;  // /proc/cpuinfo's first "model name"
  unsigned online_cpus = 0;
  std::string slug;  // e.g. "amd-epyc-2c"
};

// The CPU model lowercased, each run of other characters than [a-z0-9] one
// '-', none at either end, then "-<cpus>c": "AMD EPYC", 2 -> "amd-epyc-2c".
std::string machine_slug(std::string_view cpu_model, unsigned online_cpus);
Machine this_machine();

// The source tree's HEAD, 12 hex digits, "-dirty" when `git status
// --porcelain` lists anything outside bench/results/ (results files written
// by earlier runs do not change what is measured); "unknown" without git.
std::string source_commit();
// Now, "YYYY-MM-DD HH:MM:SS UTC".
std::string utc_date();
// /proc/loadavg's 1, 5 and 15 minute averages.
std::string load_average();
// The arguments, each shell-quoted where it needs to be.
std::string command_line(int argc, const char* const* argv);
// The environment variables that change what a bench measures (OPENBLAS_*,
// OMP_*, FAHR_*, CYCLONEDDS_*, FASTDDS_*, FASTRTPS_*), as NAME=value.
std::string relevant_environment();
// The BLAS this process has loaded (OpenBLAS: its configuration and the
// kernels it chose), or "" when none. With `load_if_absent` a process that
// links none asks the dynamic loader what libblas.so.3 would be.
std::string blas_in_use(bool load_if_absent = false);
// bench/results/<machine slug>/<name>.md under the source tree.
std::string default_results_path(std::string_view name);

class MarkdownResults {
 public:
  // What the bench prints: Markdown, or aligned plain text, which the file
  // fences as a code block so that it reads as printed.
  enum class Output { kMarkdown, kText };

  // Records the command line, then takes `--markdown`, `--markdown FILE`
  // (FILE ending in .md) or `--markdown=FILE` out of argv, so the bench's
  // own parser never sees it; argc and argv are updated. Arguments after
  // "--" are left as they are.
  MarkdownResults(int& argc, char** argv);
  ~MarkdownResults();
  MarkdownResults(const MarkdownResults&) = delete;
  MarkdownResults& operator=(const MarkdownResults&) = delete;

  bool requested() const { return requested_; }
  // For a script's results: record its command line instead of this
  // program's, and the BLAS its programs load (libblas.so.3) rather than
  // this program's, which links none.
  void record_script(std::string command) {
    command_ = std::move(command);
    script_ = true;
  }
  // For a script that writes its results after its runs: the seconds it ran
  // before (added to the footer's wall time) and the load average when it
  // began (the header's, instead of the one when the file is opened).
  void record_script_start(double elapsed_s, std::string load_average_at_start) {
    elapsed_before_s_ = elapsed_s;
    load_at_start_ = std::move(load_average_at_start);
  }
  // Without --markdown, nothing. Otherwise opens the file (FILE, or the
  // default path for `name`), writes the header and from now on copies
  // stdout into it. Throws std::runtime_error when the file cannot be written.
  void begin(std::string_view name, Output output = Output::kMarkdown);
  // Stops copying, appends the footer (wall time, load at the end), closes
  // the file and says on stderr where it is. The destructor calls it.
  void finish();

 private:
  bool requested_ = false;
  bool script_ = false;
  std::string path_;
  std::string command_;
  int fd_ = -1;
  Output output_ = Output::kMarkdown;
  std::FILE* original_stdout_ = nullptr;
  std::FILE* tee_ = nullptr;
  double start_s_ = 0.0;
  double elapsed_before_s_ = 0.0;
  std::string load_at_start_;
};

}  // namespace fahr::bench_support
