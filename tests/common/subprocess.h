// A child process for multi-process tests: started with fork/exec, stopped
// (SIGSTOP/SIGCONT) on demand, and killed when the handle goes out of scope
// so a failing test never leaves a peer behind.
#pragma once

#include <string>
#include <vector>

namespace fahr::test {

class Subprocess {
 public:
  explicit Subprocess(const std::vector<std::string>& argv);
  ~Subprocess();
  Subprocess(const Subprocess&) = delete;
  Subprocess& operator=(const Subprocess&) = delete;

  int pid() const { return pid_; }
  void signal(int signo) const;
  // Waits for exit up to timeout_ms; returns the exit status, or -1 if it
  // is still running (then it is killed).
  int wait(int timeout_ms);

 private:
  int pid_ = -1;
};

// The folder of the running test binary, to find peer executables.
std::string executable_dir();

}  // namespace fahr::test
