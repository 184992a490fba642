// The haptic service's run over DDS: its loop in real time (a tick per
// DevicePose, FEM states digested on the feed's thread) or in lockstep (a
// tick per granted base step, reading what the read rule names), and the
// lines it prints at its start and end (launchers and tests read them).
#pragma once

#include <memory>
#include <string>

#include "fahr/common/participant.h"
#include "fahr/common/service_reporter.h"
#include "fahr/haptic_service/haptic_loop.h"
#include "fahr/haptic_service/haptic_setup.h"
#include "fahr/haptic_service/tissue_feed.h"

namespace fahr::haptic_service {

// How the real-time loop waits for the next DevicePose.
struct WaitPolicy {
  // Busy-poll instead of sleeping on the subscriber: the tick starts within
  // a microsecond of the pose's arrival, at the price of a whole core.
  bool spin = false;
  // SCHED_FIFO priority of the tick thread, 0 = normal scheduling.
  int rt_priority = 0;
};

// Ticks until the duration has passed or a signal asks to stop. Blocks only
// between ticks, waiting for the next DevicePose; FEM states are digested on
// the feed's thread. Prints the run's tick figures at the end (RunReport).
// DevicePoses come from one gateway at a time and must be plausible
// (plausible_device_pose); refusals are counted in `pose_admission`.
void run_realtime(common::Participant& participant, TissueFeed& feed, HapticLoop& loop,
                  common::TickRecorder& recorder, double duration_s, const WaitPolicy& wait,
                  std::shared_ptr<common::AdmissionCounts> pose_admission);

// Returns the program's exit status.
int run_lockstep(common::Participant& participant, const HapticSetup& setup, HapticLoop& loop,
                 common::TickRecorder& recorder);

void print_ready_line(const common::Participant& participant, const HapticSetup& setup,
                      const std::string& collision, bool lockstep, double setup_s);
void print_end_line(const HapticLoop& loop);

// Finite, a unit orientation, inside a 2 m workspace, a renderable force
// and stiffness no device has (at most 1 kN, 1 MN/m): what the gateway's
// device model can produce.
bool plausible_device_pose(const msg::DevicePose& pose);

}  // namespace fahr::haptic_service
