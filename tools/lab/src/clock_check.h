// How far apart the hosts' clocks of a station are, measured by the station
// supervisors themselves: each answers clock echoes on UDP kClockEchoPort of
// its host's address, and measures every other host of the station NTP
// style (four stamps; offset = ((t2 - t1) + (t3 - t4)) / 2, error = the
// round trip minus the answer's own time, over two, of the best of many
// echoes). The table goes to clock.txt in the run folder, for reports that
// compare times stamped on different hosts (fahr_trace --clock): a one-way
// latency across hosts is printed only corrected by the offset and within
// the error. With `lab.clock_sync: chrony` and chronyc on this host, its
// own offset and bound from `chronyc -c tracking` are recorded beside.
// Clocks are fahr's (common::wall_now_ns, which a test may offset).
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "fahr/lab_plan/plan.h"

namespace fahr::lab {

inline constexpr std::uint16_t kClockEchoPort = 7399;  // below every RTPS port of the plan

struct ClockEstimate {
  std::string host, address;
  double offset_ms = 0;  // the host's clock minus this host's
  double error_ms = -1;  // < 0: not measured (no answer yet)
  std::uint64_t echoes = 0;
};

// Answers echoes and measures the station's other hosts every few seconds
// on its own threads, rewriting `file` after each round, until destroyed.
class ClockCheck {
 public:
  ClockCheck(const Plan& plan, const Station& station, const Host& self,
             std::filesystem::path file);
  ~ClockCheck();
  ClockCheck(const ClockCheck&) = delete;
  ClockCheck& operator=(const ClockCheck&) = delete;

 private:
  void answer();
  void measure();
  void write() const;

  std::filesystem::path file_;
  std::vector<ClockEstimate> hosts_;                           // hosts_[0]: this host
  std::vector<std::pair<std::string, std::string>> services_;  // service, host
  std::string chrony_;
  int answer_fd_ = -1;
  std::atomic<bool> stop_{false};
  std::thread answer_thread_, measure_thread_;
};

}  // namespace fahr::lab
